#include "calib/balls/shoot_balls.h"

#include "hdr/merge.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <exception>
#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace rsibr {

const FoundView* ShootBalls::find(const std::string& view) const {
  for (const FoundView& v : views)
    if (v.name == view) return &v;
  return nullptr;
}

int main_ball(const FoundView& view, const std::vector<ListedBall>& listed) {
  int best = -1;
  bool best_chrome = false;
  for (std::size_t b = 0; b < listed.size() && b < view.balls.size(); ++b) {
    const int k = view.balls[b].candidate;
    if (k < 0) continue;
    const bool chrome = listed[b].kind == BallKind::chrome;
    const double r = view.candidates[std::size_t(k)].loc.radius_px;
    if (best < 0 || (chrome && !best_chrome) ||
        (!chrome && !best_chrome && r > view.candidates[std::size_t(best)].loc.radius_px))
      best = k, best_chrome = best_chrome || chrome;
  }
  return best;
}

namespace {

// The share of a disc's pixels that the merge flagged as ghosts.
double ghost_share(const cv::Mat& flags, const Vec2& c, double radius) {
  if (flags.empty()) return 0;
  long disc = 0, ghost = 0;
  for (int y = std::max(0, int(c.y() - radius)); y <= std::min(flags.rows - 1, int(c.y() + radius)); ++y)
    for (int x = std::max(0, int(c.x() - radius)); x <= std::min(flags.cols - 1, int(c.x() + radius)); ++x)
      if ((Vec2(x, y) - c).squaredNorm() <= radius * radius) {
        ++disc;
        ghost += (flags.at<unsigned char>(y, x) & kGhost) != 0;
      }
  return disc > 0 ? double(ghost) / double(disc) : 0.0;
}

}  // namespace

namespace {

// One view's search: its candidates, the listed balls matched in it, the given ones located.
std::pair<FoundView, ViewCandidates> find_view_balls(const ShootBallsInput& in, const std::vector<ListedBall>& listed,
                                                     std::size_t v, std::mutex& seen_mutex) {
  const ViewImage image = in.read_view(v);
  FoundView fv;
  fv.name = in.views[v];
  fv.width = image.radiance.cols;
  fv.height = image.radiance.rows;
  // A view of another size than the lens (a crop): a pinhole of its diagonal, whose cones only
  // the lens step's far camera will make sense of.
  const bool fits = fv.width == in.lens.width() && fv.height == in.lens.height();
  fv.lens = fits ? in.lens : LensModel::pinhole(std::hypot(double(fv.width), double(fv.height)), fv.width, fv.height);
  ViewCandidates vc = view_candidates(image.radiance, fv.lens, listed, in.search);
  std::vector<char> given(listed.size(), 0);
  for (std::size_t b = 0; b < listed.size() && v < in.given.size() && b < in.given[v].size(); ++b)
    if (const auto& g = in.given[v][b]) {
      BallCandidate c;
      try {
        c = given_ball(image.radiance, fv.lens, *g);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("balls: view " + fv.name + ": ball " + listed[b].name +
                                    " given by --ball: " + e.what());
      }
      // The search's own fit of the given circle is replaced by it: kept beside it, it would be
      // another ball overlapping this one, whose disc hides all of it from the later steps.
      const auto dup = std::find_if(vc.cands.begin(), vc.cands.end(),
                                    [&](const BallCandidate& o) { return same_circle(o.loc, c.loc); });
      const int k = dup == vc.cands.end() ? int(vc.cands.size()) : int(dup - vc.cands.begin());
      if (dup == vc.cands.end())
        vc.cands.push_back(std::move(c));
      else
        *dup = std::move(c);
      for (std::size_t o = 0; o < listed.size(); ++o)
        if (o != b && vc.pick[o] == k && !given[o]) vc.pick[o] = -1;
      vc.pick[b] = k;
      given[b] = 1;
    }
  if (in.seen) {
    const std::lock_guard<std::mutex> lock(seen_mutex);
    in.seen(v, image.radiance, vc);
  }
  fv.candidates = vc.cands;
  fv.balls.resize(listed.size());
  for (std::size_t b = 0; b < listed.size(); ++b)
    if (vc.pick[b] >= 0) fv.balls[b] = {given[b] ? "given" : "found", vc.pick[b], ""};
  // A ball whose pixels the brackets disagree on has a ghost outline in the merge: found there,
  // it would be found wrong.
  if (const int k = main_ball(fv, listed); k >= 0) {
    const BallLocation& loc = fv.candidates[std::size_t(k)].loc;
    const double share = ghost_share(image.flags, loc.centre_px, loc.radius_px);
    if (share > 0.02) {
      const std::string suspect = v < in.suspect_bracket.size() ? in.suspect_bracket[v] : "";
      throw std::invalid_argument(
          "balls: view " + fv.name + ": " + std::to_string(int(std::lround(100 * share))) +
          "% of its ball's pixels disagree between brackets (a ghost: a bracket taken from another place, or cropped "
          "elsewhere); leave that bracket out of photoset.yaml" +
          (suspect.empty() ? "" : " (the one registration left furthest off: " + suspect + ")"));
    }
  }
  return {std::move(fv), std::move(vc)};
}

}  // namespace

ShootBalls find_shoot_balls(const ShootBallsInput& in) {
  if (!in.read_view) throw std::invalid_argument("balls: no reader of the merged views");
  ShootBalls out;
  out.listed = in.listed.empty() ? std::vector<ListedBall>{{"chrome", BallKind::chrome, {}}} : in.listed;
  const std::vector<ListedBall>& listed = out.listed;
  // The views in parallel (one view's search is mostly serial); the first error in view order is
  // the one reported, whichever thread met it first.
  const std::size_t n = in.views.size();
  std::vector<std::optional<std::pair<FoundView, ViewCandidates>>> found(n);
  std::vector<std::exception_ptr> errors(n);
  std::mutex seen_mutex;
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t v) {
    try {
      found[v] = find_view_balls(in, listed, v, seen_mutex);
    } catch (...) {
      errors[v] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  std::vector<std::optional<ViewCandidates>> searched;
  for (auto& f : found) {
    out.views.push_back(std::move(f->first));
    searched.push_back(std::move(f->second));
  }
  // A chrome ball no appearance test accepted, placed by its distance from another ball.
  const std::vector<ChromeRescue> rescued = rescue_chrome_balls(searched, listed, in.search);
  for (std::size_t b = 0; b < listed.size(); ++b) {
    if (listed[b].kind != BallKind::chrome) continue;
    for (std::size_t v = 0; v < out.views.size(); ++v)
      if (out.views[v].balls[b].candidate < 0 && rescued[v].candidate >= 0)
        out.views[v].balls[b] = {"rescued", rescued[v].candidate, rescued[v].note};
    break;  // the rescue places the first listed chrome ball
  }
  return out;
}

BallCandidate candidate_with_lens(const BallCandidate& c, const LensModel& lens) {
  BallCandidate out = c;
  std::vector<Vec3> rays(c.loc.outline_px.size());
  lens.unproject(c.loc.outline_px.data(), int(rays.size()), rays.data());
  // As the locator's last pass fits them: no RANSAC (the points are the outline's), Huber loss.
  ConeFitOptions fit;
  fit.ransac_iterations = 0;
  out.loc.fit = fit_cone(rays, lens, fit);
  const ConeCircle circle = cone_circle(out.loc.fit.cone, lens);
  out.loc.centre_px = circle.centre_px;
  out.loc.radius_px = circle.radius_px;
  measure_outline(out, lens);
  return out;
}

ViewCandidates candidates_for_lens(const FoundView& view, const LensModel& lens) {
  ViewCandidates vc;
  const bool same = view.lens == lens;
  for (const BallCandidate& c : view.candidates) {
    if (same) {
      vc.cands.push_back(c);
      continue;
    }
    try {
      vc.cands.push_back(candidate_with_lens(c, lens));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(view.name + ": a ball at (" + std::to_string(c.loc.centre_px.x()) + ", " +
                                  std::to_string(c.loc.centre_px.y()) + ") fits no cone through the lens: " + e.what());
    }
  }
  for (const FoundBall& b : view.balls) vc.pick.push_back(b.candidate);
  return vc;
}

}  // namespace rsibr
