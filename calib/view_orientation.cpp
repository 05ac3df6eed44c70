#include "calib/view_orientation.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <regex>
#include <stdexcept>

namespace rsibr {

namespace {

// Texture inside a candidate's disc (its inner 80%): the mean absolute difference of the log
// luminance between neighbouring pixels. A chrome ball reflects the whole world, edges compressed
// toward its rim; a grey ball shows a smooth shading, whose log range may be as large (sun and
// shadow) but changes slowly, so the pixel-to-pixel difference, not the spread, tells them apart.
double disc_texture(const cv::Mat& image, const BallGuess& g) {
  const double r = 0.8 * g.radius_px;
  auto log_lum = [&](int x, int y) {
    const cv::Vec3f p = image.at<cv::Vec3f>(y, x);
    return std::log(std::max(1e-6, (double(p[0]) + p[1] + p[2]) / 3));
  };
  double s = 0;
  int n = 0;
  const int x0 = std::max(0, int(g.centre_px.x() - r)), x1 = std::min(image.cols - 2, int(g.centre_px.x() + r));
  const int y0 = std::max(0, int(g.centre_px.y() - r)), y1 = std::min(image.rows - 2, int(g.centre_px.y() + r));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      if ((Vec2(x + 0.5, y + 0.5) - g.centre_px).norm() > r - 1) continue;
      const double v = log_lum(x, y);
      s += std::abs(log_lum(x + 1, y) - v) + std::abs(log_lum(x, y + 1) - v), n += 2;
    }
  return n > 0 ? s / n : 0;
}

// The chrome ball among the Hough candidates: each candidate (and its radius scaled by 0.8 and 1.25,
// as Hough radii in a textured scene are rough) is located (calib/ball_locator.h); a fit counts when
// most of its outline points agree (inlier fraction >= 0.6, RMS <= 0.5 px) and its radius and centre
// are plausible (within the detection range, in the image). Fits whose centres lie
// within half a radius of each other are one ball, represented by its fit with the most inliers;
// a circle inside another ball's disc is dropped (a reflection in a chrome ball); among the balls
// the most textured disc wins (a chrome ball reflects the whole world; a grey ball
// beside it often has the cleaner outline, so the outline alone would pick it).
BallLocation find_chrome_ball(const cv::Mat& img, const LensModel& lens, double rmin, double rmax, const std::string& name) {
  const std::vector<BallGuess> found = detect_balls(img, rmin, rmax, 8);
  std::vector<BallLocation> balls;
  for (const BallGuess& g : found)
    for (double scale : {1.0, 0.8, 1.25}) {
      BallLocation loc;
      try {
        loc = locate_ball(img, lens, {g.centre_px, g.radius_px * scale});
      } catch (const std::invalid_argument&) {
        continue;
      }
      const double fraction = loc.outline_px.empty() ? 0 : double(loc.fit.inliers) / loc.outline_px.size();
      if (fraction < 0.6 || !(loc.fit.rms_px <= 0.5)) continue;
      // A straight edge fits a huge circle: the radius must stay near the detection range and the
      // centre in the image.
      if (!(loc.radius_px >= rmin / 1.25 && loc.radius_px <= 1.25 * rmax) || !lens.in_image(loc.centre_px)) continue;
      auto same = std::find_if(balls.begin(), balls.end(), [&](const BallLocation& b) {
        return (b.centre_px - loc.centre_px).norm() < 0.5 * std::min(b.radius_px, loc.radius_px);
      });
      if (same == balls.end()) balls.push_back(loc);
      else if (loc.fit.inliers > same->fit.inliers) *same = loc;
    }
  if (balls.empty()) throw std::invalid_argument(name + ": no ball found");
  // A circle inside another ball's disc is something the ball reflects, not a ball.
  auto inside_another = [&](std::size_t i) {
    for (std::size_t k = 0; k < balls.size(); ++k)
      if (k != i && (balls[i].centre_px - balls[k].centre_px).norm() + balls[i].radius_px <= 1.05 * balls[k].radius_px)
        return true;
    return false;
  };
  std::size_t best = 0;
  double best_texture = -1;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (inside_another(i)) continue;
    const double t = disc_texture(img, {balls[i].centre_px, balls[i].radius_px});
    if (t > best_texture) best = i, best_texture = t;
  }
  return balls[best];
}

// "view 3" in the solver's messages -> "view 'name'".
std::string with_names(const std::string& what, const std::vector<std::string>& names) {
  std::string out;
  const std::regex re("view (\\d+)");
  auto it = std::sregex_iterator(what.begin(), what.end(), re);
  std::size_t last = 0;
  for (; it != std::sregex_iterator(); ++it) {
    const std::size_t v = std::stoul((*it)[1].str());
    out += what.substr(last, it->position() - last);
    out += v < names.size() ? "view '" + names[v] + "'" : it->str();
    last = it->position() + it->length();
  }
  out += what.substr(last);
  if (out.rfind("orientation: ", 0) == 0) out = "orient: " + out.substr(13);
  return out;
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

BallCone extraction_cone(const BallLocation& located, const ViewPose& pose, const LensModel& lens) {
  if (!pose.ball) return located.fit.cone;
  const Vec2 c = lens.project(pose.ball->axis);
  return c.allFinite() && (c - located.centre_px).norm() < 0.5 * located.radius_px ? *pose.ball : located.fit.cone;
}

PoseSet orient_views(const std::vector<std::string>& names, const std::vector<ViewImage>& views, const LensModel& lens,
                     const ViewOrientationOptions& options, ViewOrientationReport* report) {
  if (names.size() != views.size()) throw std::invalid_argument("orient: names and views differ in number");
  if (views.size() < 2) throw std::invalid_argument("orient: " + std::to_string(views.size()) + " view(s), need at least 2");
  if (!options.balls.empty() && options.balls.size() != views.size())
    throw std::invalid_argument("orient: ball guesses must be given for every view or none");
  const Mat3 gauge = gauge_world_from_first_cam(options.up);
  const double m = std::min(lens.width(), lens.height());
  const double rmin = options.min_radius_px > 0 ? options.min_radius_px : std::max(4.0, m / 40);
  const double rmax = options.max_radius_px > 0 ? options.max_radius_px : m / 2;
  ViewOrientationReport rep;
  std::vector<BallFeatures> feats;
  std::vector<CubeFeatureSet> sets;  // cube domain, for re-locating the tracks
  std::vector<BallCone> detected_cones;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const cv::Mat& img = views[v].radiance;
    if (img.type() != CV_32FC3 || img.cols != lens.width() || img.rows != lens.height())
      throw std::invalid_argument(names[v] + ": " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                                  " float RGB expected of the lens model's size " + std::to_string(lens.width()) + "x" +
                                  std::to_string(lens.height()));
    BallLocation loc;
    if (!options.balls.empty()) {
      try {
        loc = locate_ball(img, lens, options.balls[v]);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(names[v] + ": no ball found (" + e.what() + ")");
      }
    } else {
      loc = find_chrome_ball(img, lens, rmin, rmax, names[v]);
    }
    if (options.domain == FeatureDomain::cube) {
      sets.push_back(ball_cube_feature_set(img, views[v].flags, lens, loc.fit.cone, options.features, options.cube));
      feats.push_back(sets.back().features);
      if (!options.refine_tracks) sets.back().faces.clear();
    } else {
      feats.push_back(ball_features(img, lens, loc.fit.cone, options.features));
    }
    detected_cones.push_back(loc.fit.cone);
    rep.balls.push_back(loc);
    rep.features.push_back(static_cast<int>(feats.back().directions.size()));
  }
  int tracks = 0;
  const std::vector<DirectionObservation> obs = match_ball_features(feats, &tracks);
  OrientationOptions so = options.solve;
  so.first_world_from_cam = gauge;
  if (options.refine_balls) {
    // Prior: the ball centre known to the outline points' scatter (their errors are correlated along
    // the outline, so the fit's formal std dev, RMS / sqrt(points), would be far too small).
    so.balls.clear();
    for (const BallLocation& b : rep.balls) {
      const Vec3 a = b.fit.cone.axis.normalized();
      const Vec3 t = a.unitOrthogonal();
      const double h = 1e-4;
      const double px_per_rad = (lens.project((a + h * t).normalized()) - lens.project(a)).norm() / h;
      so.balls.push_back({a, b.fit.cone.half_angle, std::max(b.fit.rms_px, options.ball_prior_px) / px_per_rad,
                          options.ball_radius_prior_px / px_per_rad});
    }
  }
  OrientationSolution s;
  try {
    s = solve_orientations(static_cast<int>(views.size()), tracks, obs, so);
    if (options.domain == FeatureDomain::cube && options.refine_tracks) {
      std::vector<BallCone> refined_cones = detected_cones;
      if (options.refine_balls)
        for (std::size_t v = 0; v < views.size(); ++v) refined_cones[v] = {s.ball_axes[v], s.ball_half_angles[v]};
      const std::vector<DirectionObservation> refined =
          refine_tracks(sets, detected_cones, refined_cones, lens, options.features, s.world_from_cam, obs,
                        options.tracks, &rep.track_refinement);
      s = solve_orientations(static_cast<int>(views.size()), tracks, refined, so);
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(with_names(e.what(), names));
  }
  if (options.refine_balls)
    for (std::size_t v = 0; v < views.size(); ++v) {
      rep.balls[v].radius_px *= std::tan(s.ball_half_angles[v]) / std::tan(rep.balls[v].fit.cone.half_angle);
      rep.balls[v].fit.cone.axis = s.ball_axes[v];
      rep.balls[v].fit.cone.half_angle = s.ball_half_angles[v];
      rep.balls[v].centre_px = lens.project(s.ball_axes[v]);
    }
  rep.tracks = tracks;
  rep.observations = s.observations;
  rep.inliers = s.inliers;
  rep.rms_sigmas = s.rms_sigmas;
  if (report) *report = rep;
  for (std::size_t v = 0; v < views.size(); ++v)
    if (!std::isfinite(s.sigma_deg[v]))
      throw std::runtime_error("orient: the orientations are not determined by the features (singular covariance)");
  PoseSet out;
  out.gauge = options.up ? "up" : "first-view";
  for (std::size_t v = 0; v < views.size(); ++v) {
    out.views.push_back({names[v], s.world_from_cam[v], s.sigma_deg[v], std::nullopt});
    if (options.refine_balls) out.views.back().ball = rep.balls[v].fit.cone;
  }
  return out;
}

}  // namespace rsibr
