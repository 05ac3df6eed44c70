#include "calib/lens/outline_focal.h"

#include "calib/balls/ball_cone.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One ball's cone fitted by least squares to its (pre-filtered) outline points through `lens`.
std::optional<ConeFit> least_squares_cone(const std::vector<Vec2>& px, const LensModel& lens) {
  std::vector<Vec3> rays(px.size());
  lens.unproject(px.data(), int(px.size()), rays.data());
  ConeFitOptions o;
  o.ransac_iterations = 0;
  o.inlier_px = 1e9;  // every (pre-filtered) point counts
  o.huber_px = 1e9;   // least squares: a smooth profile in f
  o.refine_iterations = 30;
  try {
    return fit_cone(rays, lens, o);
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

// One ball's outline cost at the lens's focal length: the sum of squared pixel residuals.
double ball_cost(const std::vector<Vec2>& px, const LensModel& lens) {
  const std::optional<ConeFit> fit = least_squares_cone(px, lens);
  return fit ? fit->rms_px * fit->rms_px * double(fit->inliers) : kInf;
}

// The systematic sigma of ln f from one ball: an outline shape error of shape_px on
// its minor semi-axis b (pixels) moves its elongation e = a/b - 1 by that over b, and
//   e = cos(alpha) / sqrt(cos^2 theta - sin^2 alpha) - 1,   theta = atan(tan(theta_0) f_0 / f)
//   de / d ln f = -cos(alpha) sin^2(theta) cos^2(theta) / (cos^2 theta - sin^2 alpha)^(3/2).
// Infinite for a ball on the axis (its elongation says nothing about f).
double shape_sigma_ln_f(const ConeFit& fit, const LensModel& lens, double shape_px) {
  const double alpha = fit.cone.half_angle, theta = std::acos(std::clamp(fit.cone.axis.z(), -1.0, 1.0));
  const double c2 = std::cos(theta) * std::cos(theta) - std::sin(alpha) * std::sin(alpha);
  if (!(c2 > 0)) return kInf;
  const double slope = std::cos(alpha) * std::pow(std::sin(theta) * std::cos(theta), 2) / std::pow(c2, 1.5);
  const double b_px = lens.intrinsics()[0] * std::tan(alpha);
  return slope > 0 && b_px > 0 ? (shape_px / b_px) / slope : kInf;
}

// Minimum of a sampled profile (u log-spaced) refined by a parabola through the best sample and
// its neighbours: (u_min, curvature d2C/du2). Curvature <= 0 or a minimum at the range's end:
// unconstrained (nullopt).
struct ParabolaMin {
  double u = 0, curvature = 0, cost = 0;
};
std::optional<ParabolaMin> parabola_min(const std::vector<double>& u, const std::vector<double>& c) {
  const int n = int(u.size());
  int k = int(std::min_element(c.begin(), c.end()) - c.begin());
  if (k == 0 || k == n - 1 || !std::isfinite(c[std::size_t(k)])) return std::nullopt;
  const double h = u[1] - u[0];
  const double c0 = c[std::size_t(k - 1)], c1 = c[std::size_t(k)], c2 = c[std::size_t(k + 1)];
  const double curv = (c0 - 2 * c1 + c2) / (h * h);
  if (!(curv > 0) || !std::isfinite(curv)) return std::nullopt;
  const double du = std::clamp(-(c2 - c0) / (2 * h) / curv, -h, h);
  return ParabolaMin{u[std::size_t(k)] + du, curv, c1 - 0.5 * curv * du * du};
}

}  // namespace

LensModel with_focal(const LensModel& lens, double f) {
  std::vector<double> intr = lens.intrinsics();
  const double s = f / intr.at(0);
  intr[0] = f;
  intr[1] *= s;
  return LensModel(lens.name(), intr, lens.width(), lens.height());
}

OutlineFocal focal_from_outlines(const std::vector<std::vector<Vec2>>& outlines, const LensModel& lens,
                                 const OutlineFocalOptions& options) {
  if (lens.intrinsics().size() < 4 || !(lens.intrinsics()[0] > 0))
    throw std::invalid_argument("outline focal: the lens has no focal length to scale");
  const double f0 = lens.intrinsics()[0];
  const int nb = int(outlines.size());
  OutlineFocal out;
  out.balls.resize(std::size_t(nb));

  // Each outline thinned evenly, and its points far off its robust cone at f0 dropped (a stand, a
  // reflection's edge): the same points at every f.
  std::vector<std::vector<Vec2>> pts(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) {
    const std::vector<Vec2>& o = outlines[std::size_t(b)];
    if (o.size() < 8) continue;
    std::vector<Vec2> thin;
    const double step = std::max(1.0, double(o.size()) / options.max_points_per_ball);
    for (double i = 0; i < double(o.size()); i += step) thin.push_back(o[std::size_t(i)]);
    std::vector<Vec3> rays(thin.size());
    lens.unproject(thin.data(), int(thin.size()), rays.data());
    try {
      const ConeFit robust = fit_cone(rays, lens);
      const double keep = std::max(1.0, 3 * robust.rms_px);
      for (std::size_t i = 0; i < thin.size(); ++i)
        if (std::abs(robust.residual_px[i]) < keep) pts[std::size_t(b)].push_back(thin[i]);
    } catch (const std::invalid_argument&) {
      continue;
    }
    if (pts[std::size_t(b)].size() < 8) pts[std::size_t(b)].clear();
    out.balls[std::size_t(b)].points = int(pts[std::size_t(b)].size());
  }
  int usable = 0;
  for (const auto& p : pts) usable += p.empty() ? 0 : 1;
  if (usable == 0) throw std::invalid_argument("outline focal: no ball outline with 8 or more points");

  // The profile: every ball's cost at each f of the log-spaced grid.
  const int ng = std::max(5, options.grid);
  std::vector<double> u(static_cast<std::size_t>(ng));
  const double u0 = std::log(options.min_scale), u1 = std::log(options.max_scale);
  for (int k = 0; k < ng; ++k) u[std::size_t(k)] = u0 + (u1 - u0) * k / (ng - 1);
  std::vector<std::vector<double>> cost(std::size_t(nb), std::vector<double>(std::size_t(ng), 0.0));
  tbb::parallel_for(0, ng * nb, [&](int job) {
    const int k = job / nb, b = job % nb;
    if (pts[std::size_t(b)].empty()) return;
    cost[std::size_t(b)][std::size_t(k)] =
        ball_cost(pts[std::size_t(b)], with_focal(lens, f0 * std::exp(u[std::size_t(k)])));
  });

  // Each ball alone: its focal and sigma from its own profile (sigma in u, then pixels).
  auto sigma_u = [](double curvature, double residual_var) { return std::sqrt(2 * residual_var / curvature); };
  for (int b = 0; b < nb; ++b) {
    OutlineFocalBall& ob = out.balls[std::size_t(b)];
    if (pts[std::size_t(b)].empty()) continue;
    ob.used = true;
    const auto m = parabola_min(u, cost[std::size_t(b)]);
    const double dof = std::max(1.0, double(ob.points) - 4);
    if (m) {
      ob.focal_px = f0 * std::exp(m->u);
      ob.sigma_px = ob.focal_px * sigma_u(m->curvature, std::max(m->cost, 1e-12) / dof);
    } else {
      const auto& c = cost[std::size_t(b)];
      ob.focal_px = f0 * std::exp(u[std::size_t(std::min_element(c.begin(), c.end()) - c.begin())]);
      ob.sigma_px = kInf;
    }
  }

  // The joint profile of the used balls; a ball far from the others' joint estimate is left out
  // and the rest re-estimated (once per ball at most).
  std::string left_out;
  for (int round = 0; round <= nb; ++round) {
    std::vector<double> joint(std::size_t(ng), 0.0);
    int points = 0, balls = 0;
    for (int b = 0; b < nb; ++b) {
      if (!out.balls[std::size_t(b)].used) continue;
      for (int k = 0; k < ng; ++k) joint[std::size_t(k)] += cost[std::size_t(b)][std::size_t(k)];
      points += out.balls[std::size_t(b)].points;
      ++balls;
    }
    out.balls_used = balls;
    out.points = points;
    const auto m = parabola_min(u, joint);
    if (!m) {
      out.focal_px = f0;
      out.sigma_px = kInf;
      out.rms_px = std::sqrt(*std::min_element(joint.begin(), joint.end()) / std::max(1, points));
      out.note = "the outlines do not constrain the focal length between " +
                 std::to_string(int(f0 * options.min_scale)) + " and " + std::to_string(int(f0 * options.max_scale)) +
                 " px (balls near the image centre say little)";
      break;
    }
    // A finer look near the minimum: 9 samples a fifth of the coarse step apart.
    const double h = (u1 - u0) / (ng - 1) / 5;
    std::vector<double> uf(9), cf(9, 0.0);
    for (int k = 0; k < 9; ++k) uf[std::size_t(k)] = m->u + h * (k - 4);
    std::vector<std::vector<double>> fine(std::size_t(nb), std::vector<double>(9, 0.0));
    tbb::parallel_for(0, 9 * nb, [&](int job) {
      const int k = job / nb, b = job % nb;
      if (!out.balls[std::size_t(b)].used) return;
      fine[std::size_t(b)][std::size_t(k)] =
          ball_cost(pts[std::size_t(b)], with_focal(lens, f0 * std::exp(uf[std::size_t(k)])));
    });
    for (int b = 0; b < nb; ++b)
      for (int k = 0; k < 9; ++k) cf[std::size_t(k)] += fine[std::size_t(b)][std::size_t(k)];
    // Each ball's own estimate from the fine grid too, where its minimum lies inside it (the
    // coarse grid's parabola is biased by a fraction of its step, which would look like scatter).
    for (int b = 0; b < nb; ++b) {
      OutlineFocalBall& ob = out.balls[std::size_t(b)];
      if (!ob.used) continue;
      if (const auto pb = parabola_min(uf, fine[std::size_t(b)])) {
        ob.focal_px = f0 * std::exp(pb->u);
        ob.sigma_px =
            ob.focal_px * sigma_u(pb->curvature, std::max(pb->cost, 1e-12) / std::max(1.0, double(ob.points) - 4));
      }
    }
    const auto mf = parabola_min(uf, cf);
    const ParabolaMin best = mf ? *mf : *m;
    const double dof = std::max(1.0, double(points) - 3.0 * balls - 1);
    const double var = std::max(best.cost, 1e-12) / dof;
    out.focal_px = f0 * std::exp(best.u);
    out.sigma_px = out.focal_px * sigma_u(best.curvature, var);
    out.rms_px = std::sqrt(std::max(best.cost, 0.0) / std::max(1, points));

    // The ball that disagrees most with the joint estimate, if beyond the threshold.
    int worst = -1;
    double worst_z = options.disagreement_sigmas;
    for (int b = 0; b < nb && balls > 2; ++b) {
      const OutlineFocalBall& ob = out.balls[std::size_t(b)];
      if (!ob.used || !std::isfinite(ob.sigma_px)) continue;
      const double z = std::abs(ob.focal_px - out.focal_px) / std::hypot(ob.sigma_px, out.sigma_px);
      if (z > worst_z) {
        worst_z = z;
        worst = b;
      }
    }
    if (worst < 0) {
      // Balls that scatter more than their sigmas say (edges biased by what lies behind a
      // chrome ball's rim, a lens model's residual): the joint sigma scaled by the Birge ratio
      // sqrt(chi^2 / (n - 1)) of the balls' own estimates about it, when above 1.
      double chi2 = 0;
      int n = 0;
      for (const OutlineFocalBall& ob : out.balls)
        if (ob.used && std::isfinite(ob.sigma_px) && ob.sigma_px > 0) {
          chi2 += std::pow((ob.focal_px - out.focal_px) / ob.sigma_px, 2);
          ++n;
        }
      out.birge_ratio = n >= 3 ? std::sqrt(chi2 / (n - 1)) : 1.0;
      out.sigma_px *= std::max(1.0, out.birge_ratio);
      // The outline detector's shape error is common to every ball (the same edges, pixels and
      // filters), so it does not average down: the balls' systematic sigmas, weighted as their
      // statistical ones weigh them, added in quadrature.
      const LensModel best = with_focal(lens, out.focal_px);
      double wsum = 0, sys = 0;
      for (int b2 = 0; b2 < nb; ++b2) {
        const OutlineFocalBall& ob = out.balls[std::size_t(b2)];
        if (!ob.used || !std::isfinite(ob.sigma_px) || !(ob.sigma_px > 0)) continue;
        const std::optional<ConeFit> fit = least_squares_cone(pts[std::size_t(b2)], best);
        if (!fit) continue;
        const double sb = shape_sigma_ln_f(*fit, best, options.shape_systematic_px);
        if (!std::isfinite(sb)) continue;  // a ball on the axis: no elongation, no weight either
        const double w = 1 / (ob.sigma_px * ob.sigma_px);
        wsum += w;
        sys += w * sb;
      }
      out.systematic_px = wsum > 0 ? out.focal_px * sys / wsum : kInf;
      out.sigma_px = std::hypot(out.sigma_px, out.systematic_px);
      break;
    }
    out.balls[std::size_t(worst)].used = false;
    left_out += (left_out.empty() ? "" : ", ") + std::to_string(worst);
  }
  if (!left_out.empty())
    out.note += (out.note.empty() ? "" : "; ") + std::string("outlines left out (their own focal length disagrees): ") +
                left_out;
  return out;
}

}  // namespace rsibr
