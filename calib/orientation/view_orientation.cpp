#include "calib/orientation/view_orientation.h"

#include "calib/orientation/consensus_chance.h"
#include "core/keep_where.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

namespace rsibr {

namespace {

// The solve's error in the user's terms: the view's name for its index.
std::invalid_argument named(const OrientationError& e, const std::vector<std::string>& names) {
  std::string view;
  if (e.view() >= 0)
    view = std::size_t(e.view()) < names.size() ? "view '" + names[std::size_t(e.view())] + "': "
                                                : "view " + std::to_string(e.view()) + ": ";
  return std::invalid_argument("orient: " + view + e.problem());
}

}  // namespace

Mat3 gauge_world_from_first_cam(const std::optional<Vec3>& up) {
  if (!up) return Mat3::Identity();
  if (!up->allFinite() || !(up->norm() > 1e-12)) throw std::invalid_argument("--up: must be a non-zero finite vector");
  // World axes in the first camera's frame: Y = up, Z = the camera's forward made horizontal.
  const Vec3 y = up->normalized();
  Vec3 z = Vec3(0, 0, 1) - y.z() * y;
  if (z.norm() < 1e-6) z = Vec3(0, -1, 0) - (-y.y()) * y;  // looking straight up or down: the camera's -y
  z.normalize();
  const Vec3 x = y.cross(z);
  Mat3 cam_from_world;
  cam_from_world << x, y, z;
  return cam_from_world.transpose();
}

WorldUp level_pose_set(PoseSet& poses, const WorldUpOptions& options, const std::vector<VerticalLine>& lines,
                       const std::vector<char>& in_estimate) {
  if (poses.views.empty()) throw std::invalid_argument("level: no views");
  if (!in_estimate.empty() && in_estimate.size() != poses.views.size())
    throw std::invalid_argument("level: in_estimate must be given for every view or none");
  std::vector<Mat3> r;
  for (std::size_t v = 0; v < poses.views.size(); ++v)
    if (in_estimate.empty() || in_estimate[v]) r.push_back(poses.views[v].world_from_cam);
  if (r.empty()) throw std::invalid_argument("level: no view joins the estimate");
  WorldUp wu = estimate_world_up(r, lines, options);
  // Every view's roll from level, the views left out included (their roll shows why).
  wu.roll_deg.clear();
  for (const ViewPose& v : poses.views)
    wu.roll_deg.push_back(std::asin(std::clamp(v.world_from_cam.col(0).dot(wu.up), -1.0, 1.0)) * 180 / kPi);
  // Up in the first camera's frame; the new world from the first camera is the gauge's.
  const Mat3 first_from_world = poses.views.front().world_from_cam.transpose();
  wu.up = (first_from_world * wu.up).normalized();
  const Mat3 new_from_old = gauge_world_from_first_cam(wu.up) * first_from_world;
  for (ViewPose& v : poses.views) v.world_from_cam = new_from_old * v.world_from_cam;
  poses.gauge = "estimated-up";
  return wu;
}

BallCone extraction_cone(const BallLocation& located, const ViewPose& pose, const LensModel& lens) {
  if (!pose.ball) return located.fit.cone;
  const Vec2 c = lens.project(pose.ball->axis);
  return c.allFinite() && (c - located.centre_px).norm() < 0.5 * located.radius_px ? *pose.ball : located.fit.cone;
}

namespace {

std::vector<ListedBall> balls_or_one_chrome(const std::vector<ListedBall>& listed) {
  return listed.empty() ? std::vector<ListedBall>{{"chrome", BallKind::chrome, {}}} : listed;
}

int chrome_index(const ViewCandidates& vc, const std::vector<ListedBall>& balls) {
  for (std::size_t b = 0; b < balls.size(); ++b)
    if (balls[b].kind == BallKind::chrome && vc.pick[b] >= 0) return vc.pick[b];
  return -1;
}

std::optional<BallCandidate> chrome_of(const ViewCandidates& vc, int k, std::vector<BallLocation>* overlapping) {
  if (k < 0) return std::nullopt;
  const BallCandidate& chrome = vc.cands[std::size_t(k)];
  if (overlapping)
    for (std::size_t i = 0; i < vc.cands.size(); ++i) {
      const BallLocation& o = vc.cands[i].loc;
      if (int(i) != k && !same_circle(o, chrome.loc) &&
          (o.centre_px - chrome.loc.centre_px).norm() < o.radius_px + chrome.loc.radius_px &&
          o.radius_px > 0.5 * chrome.loc.radius_px && o.radius_px < 2 * chrome.loc.radius_px)
        overlapping->push_back(o);
    }
  return chrome;
}

}  // namespace

std::optional<BallCandidate> find_chrome_ball(const cv::Mat& image, const LensModel& lens,
                                              const std::vector<ListedBall>& listed, const BallSearchOptions& search,
                                              std::vector<BallLocation>* overlapping) {
  const std::vector<ListedBall> balls = balls_or_one_chrome(listed);
  const ViewCandidates vc = view_candidates(image, lens, balls, search);
  return chrome_of(vc, chrome_index(vc, balls), overlapping);
}

namespace {

// `flags` with the clipped bit set over the discs of `balls` (another ball in front of the chrome
// one shows itself, not the world: its pixels must give no features).
cv::Mat masked_flags(const cv::Mat& flags, const cv::Size& size, const std::vector<BallLocation>& balls) {
  cv::Mat out = flags.empty() ? cv::Mat::zeros(size, CV_8UC1) : flags.clone();
  for (const BallLocation& b : balls)
    cv::circle(out, cv::Point(int(std::lround(b.centre_px.x())), int(std::lround(b.centre_px.y()))),
               int(std::ceil(b.radius_px + std::max(2.0, 0.05 * b.radius_px))), cv::Scalar(1), cv::FILLED);
  return out;
}

}  // namespace

namespace {

using PairSearches = std::map<std::pair<std::string, std::string>, RotationSearch>;

// The searched rotation taking view a's camera frame to view b's, or nullopt.
std::optional<std::pair<Mat3, double>> searched(const PairSearches& searches, const std::string& a,
                                                const std::string& b) {
  if (auto it = searches.find({a, b}); it != searches.end())
    return std::make_pair(it->second.b_from_a, it->second.score);
  if (auto it = searches.find({b, a}); it != searches.end())
    return std::make_pair(Mat3(it->second.b_from_a.transpose()), it->second.score);
  return std::nullopt;
}

// Rotations chained along a maximum spanning tree of the searched pairs (Prim, from the first
// view; pairs under min_score are no edges): W_b = W_a (b_from_a)^T. Views it does not reach get
// none.
std::vector<std::optional<Mat3>> chained_rotations(const std::vector<std::string>& names, const PairSearches& searches,
                                                   double min_score) {
  std::vector<std::optional<Mat3>> w(names.size());
  if (names.empty()) return w;
  w[0] = Mat3::Identity();
  for (;;) {
    double best = -2;
    std::size_t from = 0, to = 0;
    Mat3 b_from_a = Mat3::Identity();
    for (std::size_t i = 0; i < names.size(); ++i)
      for (std::size_t j = 0; j < names.size(); ++j) {
        if (!w[i] || w[j]) continue;
        const auto r = searched(searches, names[i], names[j]);
        if (r && r->second >= min_score && r->second > best) best = r->second, from = i, to = j, b_from_a = r->first;
      }
    if (best < -1) break;
    w[to] = Mat3(*w[from] * b_from_a.transpose());
  }
  return w;
}

// The picked points' observations in the views placed (`names`, their balls as located): the
// pixel's camera ray reflected off the ball, sigma = sigma_px x the angle one pixel turns it
// there. Feature ids from first_id on, one per point seen in two or more of these views. Throws
// std::invalid_argument naming the point for a view not in the shoot or a pixel off the ball.
std::vector<DirectionObservation> picked_observations(const PointPairs& points, const std::vector<std::string>& names,
                                                      const std::vector<BallLocation>& balls, const LensModel& lens,
                                                      int first_id) {
  std::vector<DirectionObservation> out;
  int id = first_id;
  for (const PickedPoint& p : points.points) {
    std::vector<DirectionObservation> seen;
    for (const auto& [view, px] : p.seen) {
      const auto it = std::find(names.begin(), names.end(), view);
      if (it == names.end()) continue;  // not in the shoot: checked by the caller; left out: skipped
      const std::size_t v = std::size_t(it - names.begin());
      const BallLocation& b = balls[v];
      char at[160];
      std::snprintf(at, sizeof at, "%s.%s: (%.1f, %.1f)", p.where.c_str(), view.c_str(), px.x(), px.y());
      if (!((px - b.centre_px).norm() < 0.98 * b.radius_px))
        throw std::invalid_argument(std::string(at) + " is not on the chrome ball (centre (" +
                                    std::to_string(int(std::lround(b.centre_px.x()))) + ", " +
                                    std::to_string(int(std::lround(b.centre_px.y()))) + "), radius " +
                                    std::to_string(int(std::lround(b.radius_px))) + " px)");
      const double s = std::sin(b.fit.cone.half_angle);
      auto reflected = [&](const Vec2& q) {
        return reflect_off_ball<double>(lens.unproject(q).normalized(), b.fit.cone.axis, s).normalized().eval();
      };
      const Vec3 r = reflected(px);
      const double per_px =
          2 * std::max(angle_between(r, reflected(px + Vec2(0.5, 0))), angle_between(r, reflected(px + Vec2(0, 0.5))));
      DirectionObservation o;
      o.view = int(v), o.feature = id, o.direction = r, o.sigma = std::max(points.sigma_px * per_px, 1e-6);
      o.ray = lens.unproject(px).normalized();
      seen.push_back(o);
    }
    if (seen.size() < 2) continue;
    for (const DirectionObservation& o : seen) out.push_back(o);
    ++id;
  }
  return out;
}

std::vector<PairOrientation> pair_report(const std::vector<std::string>& names, const std::vector<BallFeatures>& feats,
                                         const std::vector<PairMatches>& matches, const PairSearches& searches,
                                         const OrientationSolution& s, const std::vector<DirectionObservation>& obs,
                                         double inlier_deg, double gate_deg) {
  // Per track: its observation in each view.
  std::map<int, std::map<int, const DirectionObservation*>> tracks;
  for (const DirectionObservation& o : obs) tracks[o.feature][o.view] = &o;
  const auto pixel = [&](const DirectionObservation& o) -> std::optional<Vec2> {
    if (o.index < 0 || std::size_t(o.view) >= feats.size() ||
        std::size_t(o.index) >= feats[std::size_t(o.view)].pixels.size())
      return std::nullopt;
    return feats[std::size_t(o.view)].pixels[std::size_t(o.index)];
  };
  std::vector<PairOrientation> out;
  for (const PairMatches& m : matches) {
    if (std::size_t(m.b) >= names.size()) continue;
    PairOrientation p;
    p.a = names[std::size_t(m.a)], p.b = names[std::size_t(m.b)];
    p.features_a = m.features_a, p.features_b = m.features_b, p.matched = m.matched, p.gated = m.gated;
    const std::size_t ia_ = std::size_t(m.a), ib_ = std::size_t(m.b);
    const bool solved = ib_ < s.world_from_cam.size() &&
                        (s.oriented.empty() ||
                         (ia_ < s.oriented.size() && ib_ < s.oriented.size() && s.oriented[ia_] && s.oriented[ib_]));
    for (const auto& [id, seen] : tracks) {
      const auto ia = seen.find(m.a), ib = seen.find(m.b);
      if (ia == seen.end() || ib == seen.end()) continue;
      ++p.shared_tracks;
      const bool inlier =
          solved && angle_between(s.world_from_cam[std::size_t(m.a)] * ia->second->direction,
                                  s.world_from_cam[std::size_t(m.b)] * ib->second->direction) < inlier_deg * kPi / 180;
      p.inliers += inlier;
      const auto pa = pixel(*ia->second), pb = pixel(*ib->second);
      if (pa && pb) p.matches_px.push_back({*pa, *pb}), p.match_inlier.push_back(inlier);
    }
    if (m.gated) p.chance_inliers = p.shared_tracks * std::min(1.0, std::pow(inlier_deg / gate_deg, 2));
    if (auto it = searches.find({p.a, p.b}); it != searches.end()) {
      const RotationSearch& r = it->second;
      p.search_score = r.score, p.search_runner_up = r.runner_up, p.search_overlap = r.overlap;
      p.search_angle_deg = Eigen::AngleAxisd(r.b_from_a).angle() * 180 / kPi;
      if (solved) {
        const Mat3 b_from_a = s.world_from_cam[std::size_t(m.b)].transpose() * s.world_from_cam[std::size_t(m.a)];
        p.solved_vs_search_deg = Eigen::AngleAxisd(b_from_a * r.b_from_a.transpose()).angle() * 180 / kPi;
      }
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace

namespace {
PoseSet orient_views_reporting(const std::vector<std::string>& all_names, const std::vector<ViewImage>& all_views,
                               const LensModel& lens, const ViewOrientationOptions& options,
                               ViewOrientationReport& rep);
}  // namespace

PoseSet orient_views(const std::vector<std::string>& all_names, const std::vector<ViewImage>& all_views,
                     const LensModel& lens, const ViewOrientationOptions& options, ViewOrientationReport* report) {
  ViewOrientationReport rep;
  try {
    PoseSet out = orient_views_reporting(all_names, all_views, lens, options, rep);
    if (report) *report = std::move(rep);
    return out;
  } catch (...) {
    if (report) *report = std::move(rep);  // what was found before it stopped
    throw;
  }
}

namespace {

PoseSet orient_views_reporting(const std::vector<std::string>& all_names, const std::vector<ViewImage>& all_views,
                               const LensModel& lens, const ViewOrientationOptions& options,
                               ViewOrientationReport& rep) {
  if (all_names.size() != all_views.size()) throw std::invalid_argument("orient: names and views differ in number");
  // One view is a shoot (the paper's own capture): its camera is the world frame, levelled below.
  if (all_views.empty()) throw std::invalid_argument("orient: no views");
  const bool single = all_views.size() == 1;
  if (!options.balls.empty() && options.balls.size() != all_views.size())
    throw std::invalid_argument("orient: ball guesses must be given for every view or none");
  if (!options.given_chrome.empty() && options.given_chrome.size() != all_views.size())
    throw std::invalid_argument("orient: given chrome balls must be listed for every view or none");
  if (!options.known_world_from_cam.empty() && options.known_world_from_cam.size() != all_views.size())
    throw std::invalid_argument("orient: known rotations must be given for every view or none");
  const Mat3 gauge = gauge_world_from_first_cam(options.up);
  for (const PickedPoint& p : options.points.points)
    for (const auto& [view, px] : p.seen)
      if (std::find(all_names.begin(), all_names.end(), view) == all_names.end())
        throw std::invalid_argument(p.where + ": no view '" + view + "' in the shoot");
  std::vector<BallFeatures> feats;
  std::vector<CubeFeatureSet> sets;  // cube domain, for re-locating the tracks
  std::vector<BallCone> detected_cones;
  // Per view placed, with search_rotations: what its panorama is made from (made only if needed).
  struct PanoramaSource {
    std::size_t image;
    cv::Mat flags;
    BallCone cone;
  };
  std::vector<PanoramaSource> panoramas;
  std::vector<std::string> names;
  std::vector<Mat3> known;
  for (std::size_t v = 0; v < all_views.size(); ++v) {
    const cv::Mat& img = all_views[v].radiance;
    if (img.type() != CV_32FC3 || img.cols != lens.width() || img.rows != lens.height())
      throw std::invalid_argument(all_names[v] + ": " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                                  " float RGB expected of the lens model's size " + std::to_string(lens.width()) + "x" +
                                  std::to_string(lens.height()));
  }
  // Candidates of the views whose chrome ball is searched for, then the cross-view rescue.
  const std::vector<ListedBall> balls = balls_or_one_chrome(options.listed);
  std::vector<std::optional<ViewCandidates>> searched(all_views.size());
  std::vector<ChromeRescue> rescued(all_views.size());
  if (!options.candidates.empty()) {
    if (options.candidates.size() != all_views.size())
      throw std::invalid_argument("orient: candidates must be given for every view or none");
    for (std::size_t v = 0; v < all_views.size(); ++v) {
      if (options.candidates[v].pick.size() != balls.size())
        throw std::invalid_argument("orient: " + all_names[v] + ": candidates picked for " +
                                    std::to_string(options.candidates[v].pick.size()) + " balls, " +
                                    std::to_string(balls.size()) + " listed");
      searched[v] = options.candidates[v];
    }
  } else {
    for (std::size_t v = 0; v < all_views.size(); ++v) {
      const bool given = (!options.given_chrome.empty() && options.given_chrome[v]) || !options.balls.empty();
      if (!given) searched[v] = view_candidates(all_views[v].radiance, lens, balls, options.search);
    }
    rescued = rescue_chrome_balls(searched, balls, options.search);
  }
  for (std::size_t v = 0; v < all_views.size(); ++v) {
    const cv::Mat& img = all_views[v].radiance;
    std::optional<BallCandidate> found;
    std::vector<BallLocation> overlapping;
    const std::optional<BallGuess> guess =
        !options.given_chrome.empty() && options.given_chrome[v]
            ? options.given_chrome[v]
            : (!options.balls.empty() ? std::optional<BallGuess>(options.balls[v]) : std::nullopt);
    if (guess) {
      try {
        found = given_ball(img, lens, *guess);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(all_names[v] + ": no ball found (" + e.what() + ")");
      }
    } else {
      const int k = chrome_index(*searched[v], balls);
      found = chrome_of(*searched[v], k >= 0 ? k : rescued[v].candidate, &overlapping);
      if (k < 0 && found) rep.notes.push_back(all_names[v] + ": " + rescued[v].note);
    }
    if (!found) {
      rep.left_out.push_back(all_names[v] +
                             ": no chrome ball found (no candidate with a clean outline that looks like a mirror)");
      continue;
    }
    // Another ball overlapping the chrome one may be in front: its edge is no part of the chrome
    // ball's outline.
    if (!overlapping.empty()) found->loc = refit_outline_excluding(found->loc, lens, overlapping);
    const BallLocation& loc = found->loc;
    const cv::Mat flags =
        overlapping.empty() ? all_views[v].flags : masked_flags(all_views[v].flags, img.size(), overlapping);
    if (options.search_rotations && options.known_world_from_cam.empty()) panoramas.push_back({v, flags, loc.fit.cone});
    if (options.domain == FeatureDomain::cube) {
      sets.push_back(ball_cube_feature_set(img, flags, lens, loc.fit.cone, options.features, options.cube));
      feats.push_back(sets.back().features);
      if (!options.refine_tracks) sets.back().faces.clear();
    } else {
      feats.push_back(ball_features(img, lens, loc.fit.cone, options.features));
    }
    detected_cones.push_back(loc.fit.cone);
    rep.balls.push_back(loc);
    rep.measured.push_back(*found);
    rep.features.push_back(static_cast<int>(feats.back().directions.size()));
    names.push_back(all_names[v]);
    if (!options.known_world_from_cam.empty()) known.push_back(options.known_world_from_cam[v]);
  }
  if (!options.known_world_from_cam.empty() && names.empty()) {
    // Known rotations: nothing to refine; the views without a chrome ball keep no ball.
    return PoseSet{};
  }
  if (names.size() < 2 && known.empty() && !(single && names.size() == 1)) {
    std::string why = "orient: a chrome ball was found in " + std::to_string(names.size()) + " of " +
                      std::to_string(all_views.size()) + " views, need at least " + (single ? "1" : "2");
    if (!rep.left_out.empty()) why += " (" + rep.left_out.front() + ")";
    // The one hint a failed search needs: where the ball is (rsibr balls lists what was seen).
    why +=
        "; give it by hand (rsibr process --ball VIEW:BALL=X,Y,R; rsibr balls hdr/VIEW.exr --picture FILE.png "
        "shows the candidates)";
    throw std::invalid_argument(why);
  }
  if (names.empty()) throw std::invalid_argument("orient: " + rep.left_out.front());
  OrientationOptions so = options.solve;
  so.first_world_from_cam = known.empty() ? gauge : known.front();
  auto ball_priors = [&] {
    // Prior: the ball centre known to the outline points' scatter (their errors are correlated along
    // the outline, so the fit's formal std dev, RMS / sqrt(points), would be far too small).
    so.balls.clear();
    if (!options.refine_balls) return;
    for (const BallLocation& b : rep.balls) {
      const Vec3 a = b.fit.cone.axis.normalized();
      const Vec3 t = a.unitOrthogonal();
      const double h = 1e-4;
      const double px_per_rad = (lens.project((a + h * t).normalized()) - lens.project(a)).norm() / h;
      so.balls.push_back({a, b.fit.cone.half_angle, std::max(b.fit.rms_px, options.ball_prior_px) / px_per_rad,
                          options.ball_radius_prior_px / px_per_rad});
    }
  };
  // Views the features cannot place are left out (reported), and the rest solved again. Before
  // anyone is left out, the features are matched once more under the rotations the panoramas
  // give (every pair searched, by name: views left out later keep theirs).
  PairSearches searches;
  std::map<std::size_t, ReflectionPanorama> made;  // by image index
  const auto panorama_of = [&](std::size_t v) -> const ReflectionPanorama& {
    const PanoramaSource& src = panoramas[v];
    auto it = made.find(src.image);
    if (it == made.end())
      it = made.emplace(src.image,
                        reflection_panorama(all_views[src.image].radiance, src.flags, lens, src.cone, options.panorama))
               .first;
    return it->second;
  };
  bool gated = false;
  int tracks = 0;
  std::vector<DirectionObservation> obs;
  std::vector<PairMatches> pair_matches;
  std::optional<OrientationSolution> solved;  // the first solve, when every view was placed
  std::set<std::string> beyond_chance;        // views whose unguided matches passed the chance test
  for (;;) {
    MatchGuess guess;
    if (gated) {
      for (std::size_t i = 0; i < names.size(); ++i)
        for (std::size_t j = i + 1; j < names.size(); ++j)
          if (!searches.count({names[i], names[j]}))
            searches[{names[i], names[j]}] = search_rotation(panorama_of(i), panorama_of(j), options.rotation_search);
      guess.world_from_cam = chained_rotations(names, searches, options.min_search_score);
      guess.gate_deg = options.gate_deg;
    }
    if (options.match_features) {
      obs = match_ball_features(feats, &tracks, 0.75, guess, &pair_matches);
    } else {
      obs.clear(), pair_matches.clear(), tracks = 0;
    }
    // Points picked by hand: one more track each, after the features'.
    std::vector<char> picked(names.size(), 0);
    for (const DirectionObservation& o : picked_observations(options.points, names, rep.balls, lens, tracks)) {
      obs.push_back(o);
      picked[std::size_t(o.view)] = 1;
      tracks = std::max(tracks, o.feature + 1);
    }
    so.fixed_world_from_cam = known;
    ball_priors();
    if (!known.empty() || names.size() < 2) break;
    OrientationOptions probe = so;
    probe.leave_out_unplaced = true;
    OrientationSolution first;
    try {
      first = solve_orientations(static_cast<int>(names.size()), tracks, obs, probe);
    } catch (const OrientationError& e) {
      throw named(e, names);
    }
    rep.pairs = pair_report(names, feats, pair_matches, searches, first, obs, so.inlier_deg,
                            options.gate_deg);  // kept if it stops
    std::vector<char> keep = first.oriented;
    const std::vector<ChanceTest> chance =
        consensus_against_chance(obs, first, guess.world_from_cam, options.consensus_deg, options.gate_deg, !gated);
    // Under searched rotations, a view whose matches agree no better than chance is not placed,
    // unless its unguided matches already agreed beyond chance: under the gate chance is larger by
    // construction (its matches were sought near the guess). Unguided agreement is not a test of
    // its own: the raw directions (before the balls' refinement) can miss the 2-degree consensus on a
    // view the solve places correctly (README's main job: view01, 2 of 76, 0.6 degrees off).
    for (std::size_t v = 0; v < keep.size() && !gated; ++v)
      if (keep[v] && chance[v].matched > 0 && chance[v].p_value <= options.max_chance) beyond_chance.insert(names[v]);
    for (std::size_t v = 1; v < keep.size() && gated; ++v)
      if (keep[v] && !picked[v] && !beyond_chance.count(names[v]) && chance[v].matched > 0 &&
          !(chance[v].p_value <= options.max_chance)) {
        keep[v] = 0;
        char why[200];
        std::snprintf(why, sizeof why,
                      "has %d matched pairs that agree no better than chance would (%d within %.3g degrees; chance "
                      "gives %.1f)",
                      chance[v].matched, chance[v].agreeing, options.consensus_deg, chance[v].expected);
        first.left_out[v] = why;
      }
    if (std::count(keep.begin(), keep.end(), 1) == static_cast<long>(keep.size())) {
      solved = std::move(first);
      break;
    }
    if (!gated && panoramas.size() == names.size()) {
      gated = true;
      continue;
    }
    for (std::size_t v = 0; v < keep.size(); ++v)
      if (!keep[v]) rep.left_out.push_back(names[v] + ": its chrome ball " + first.left_out[v]);
    auto filter = [&](auto& vec) { keep_where(vec, keep); };
    filter(feats), filter(detected_cones), filter(rep.balls), filter(rep.measured), filter(rep.features), filter(names);
    if (!sets.empty()) filter(sets);
    if (!panoramas.empty()) filter(panoramas);
    if (names.size() < 2)
      throw std::invalid_argument("orient: only " + std::to_string(names.size()) + " view(s) could be oriented (" +
                                  rep.left_out.back() +
                                  "); tie the views together by hand: points picked in their chrome balls, "
                                  "--points FILE.yaml (the guide shows how)");
  }
  const std::size_t n = names.size();
  OrientationSolution s;
  std::vector<DirectionObservation> obs_used = obs;
  const int nv = static_cast<int>(n);
  try {
    if (n == 1 || (!known.empty() && obs.empty())) {
      // Known rotations and nothing matched (or one view): the balls stay as located; a lone view
      // without a known rotation is the gauge itself.
      s.world_from_cam = known.empty() ? std::vector<Mat3>{so.first_world_from_cam} : known;
      s.sigma_deg.assign(n, 0.0);
      for (const BallLocation& b : rep.balls)
        s.ball_axes.push_back(b.fit.cone.axis), s.ball_half_angles.push_back(b.fit.cone.half_angle);
    } else {
      s = solved ? *solved : solve_orientations(nv, tracks, obs, so);
      if (options.domain == FeatureDomain::cube && options.refine_tracks) {
        std::vector<BallCone> refined_cones = detected_cones;
        if (options.refine_balls)
          for (std::size_t v = 0; v < n; ++v) refined_cones[v] = {s.ball_axes[v], s.ball_half_angles[v]};
        // Features only: a picked point has no patch on the cube faces and keeps its observations.
        std::vector<DirectionObservation> features, refined;
        for (const DirectionObservation& o : obs) (o.index >= 0 ? features : refined).push_back(o);
        const std::vector<DirectionObservation> relocated =
            refine_tracks(sets, detected_cones, refined_cones, lens, options.features, s.world_from_cam, features,
                          options.tracks, &rep.track_refinement);
        refined.insert(refined.begin(), relocated.begin(), relocated.end());
        s = solve_orientations(nv, tracks, refined, so);
        obs_used = refined;
      }
    }
  } catch (const OrientationError& e) {
    throw named(e, names);
  }
  if (options.refine_balls)
    for (std::size_t v = 0; v < n; ++v) {
      rep.balls[v].radius_px *= std::tan(s.ball_half_angles[v]) / std::tan(rep.balls[v].fit.cone.half_angle);
      rep.balls[v].fit.cone.axis = s.ball_axes[v];
      rep.balls[v].fit.cone.half_angle = s.ball_half_angles[v];
      rep.balls[v].centre_px = lens.project(s.ball_axes[v]);
    }
  for (std::size_t v = 0; v < n; ++v)
    if (!std::isfinite(s.sigma_deg[v]))
      throw std::runtime_error("orient: the orientations are not determined by the features (singular covariance)");
  rep.pairs = pair_report(names, feats, pair_matches, searches, s, obs_used, so.inlier_deg, options.gate_deg);
  // Where both views of a pair see the same direction, how well their radiances agree.
  for (PairOrientation& p : rep.pairs) {
    const auto view = [&](const std::string& name) {
      return std::size_t(std::find(names.begin(), names.end(), name) - names.begin());
    };
    const std::size_t a = view(p.a), b = view(p.b);
    const auto image = [&](std::size_t v) -> const ViewImage& {
      return all_views[std::size_t(std::find(all_names.begin(), all_names.end(), names[v]) - all_names.begin())];
    };
    const auto cone = [&](std::size_t v) { return rep.balls[v].fit.cone; };  // refined above when refine_balls
    p.agreement = view_agreement(image(a), cone(a), s.world_from_cam[a], image(b), cone(b), s.world_from_cam[b], lens);
  }
  rep.names = names;
  rep.tracks = tracks;
  rep.observations = s.observations;
  rep.inliers = s.inliers;
  rep.rms_sigmas = s.rms_sigmas;
  PoseSet out;
  out.gauge = options.up ? "up" : "first-view";
  for (std::size_t v = 0; v < n; ++v) {
    out.views.push_back({names[v], s.world_from_cam[v], s.sigma_deg[v], std::nullopt});
    if (options.refine_balls) out.views.back().ball = rep.balls[v].fit.cone;
  }
  // The solve's world is the first oriented camera's frame: levelled by the estimated up, with the
  // stands under the chrome balls as vertical lines where they show; views whose balls disagree
  // with the rig stay out of it.
  if (known.empty() && !options.up && options.estimate_up) {
    rep.rig_disagreement.assign(n, -1.0);
    rep.rig_suspect.assign(n, 0);
    const bool other_balls =
        std::count_if(balls.begin(), balls.end(), [](const ListedBall& b) { return b.kind != BallKind::chrome; }) > 0;
    if (options.rig_check && other_balls && n >= 3) {
      std::vector<ViewBalls> vb(n);
      std::vector<std::size_t> image_of(n);
      for (std::size_t v = 0; v < n; ++v) {
        image_of[v] = std::size_t(std::find(all_names.begin(), all_names.end(), names[v]) - all_names.begin());
        vb[v].name = names[v];
        if (searched[image_of[v]]) vb[v].candidates = searched[image_of[v]]->cands;
        vb[v].chrome = rep.balls[v].fit.cone;
        vb[v].world_from_cam = s.world_from_cam[v];
      }
      const std::vector<RigMember> rig = fit_ball_rig(vb, balls);
      for (std::size_t v = 0; v < n; ++v) {
        if (vb[v].candidates.empty()) continue;
        for (const BallFinding& f : identify_view_balls(vb[v], rig, balls, all_views[image_of[v]].radiance, lens))
          if (f.found() && f.disagreement > 0)
            rep.rig_disagreement[v] = std::max(rep.rig_disagreement[v], f.disagreement);
      }
      const RigSuspects sus = rig_suspects(rep.rig_disagreement, options.rig_suspect);
      rep.rig_suspect = sus.suspect;
      for (std::size_t v = 0; v < n; ++v)
        if (rep.rig_suspect[v]) {
          char note[220];
          std::snprintf(note, sizeof note,
                        "its other balls lie %.2f chrome radii from where the rig puts them (median of the views "
                        "%.2f): its chrome ball or its rotation is off; left out of the world-up estimate",
                        rep.rig_disagreement[v], sus.median);
          rep.notes.push_back(names[v] + ": " + note);
        }
    }
    std::vector<VerticalLine> lines;
    for (std::size_t v = 0; v < n && options.stand_lines; ++v) {
      if (rep.rig_suspect[v]) continue;
      const std::size_t i = std::size_t(std::find(all_names.begin(), all_names.end(), names[v]) - all_names.begin());
      if (const auto line = find_stand_line(all_views[i].radiance, lens, rep.balls[v].fit.cone, options.stand))
        lines.push_back({s.world_from_cam[v] * line->plane_normal, line->sigma_deg, names[v] + ": stand"});
    }
    // One stand seen from every view: its tilt is common to all its lines.
    for (VerticalLine& l : lines)
      l.sigma_deg = std::max(l.sigma_deg, options.stand.verticality_deg * std::sqrt(double(lines.size())));
    std::vector<char> in_estimate(n);
    for (std::size_t v = 0; v < n; ++v) in_estimate[v] = !rep.rig_suspect[v];
    rep.world_up = level_pose_set(out, options.up_options, lines, in_estimate);
  }
  return out;
}

}  // namespace

}  // namespace rsibr
