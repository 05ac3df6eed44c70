#include "calib/balls/ball_cone.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace rsibr {

double cone_residual(const BallCone& cone, const Vec3& ray) { return angle_between(ray, cone.axis) - cone.half_angle; }

// sum w_i (d_i . w - 1)^2 -> normal equations (sum w_i d_i d_i^T) w = sum w_i d_i.
std::optional<BallCone> fit_cone_algebraic(const std::vector<Vec3>& rays, const std::vector<double>& weights) {
  if (rays.size() < 3) return std::nullopt;
  Mat3 a = Mat3::Zero();
  Vec3 b = Vec3::Zero();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    a += w * rays[i] * rays[i].transpose();
    b += w * rays[i];
  }
  Eigen::JacobiSVD<Mat3> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 sv = svd.singularValues();
  if (!(sv(2) > 1e-14 * sv(0))) return std::nullopt;
  const Vec3 w = svd.solve(b);
  const double len = w.norm();
  if (!std::isfinite(len) || len <= 1.0) return std::nullopt;  // cos(alpha) = 1/|w| must be < 1
  BallCone cone;
  cone.axis = w / len;
  cone.half_angle = std::acos(1.0 / len);
  if (!(cone.half_angle > 0 && cone.half_angle < kPi / 2)) return std::nullopt;
  return cone;
}

double pixels_per_radian(const LensModel& lens, const Vec3& axis, const Vec3& d) {
  Vec3 e = d - d.dot(axis) * axis;  // d = cos(theta) axis + sin(theta) e
  const double en = e.norm();
  if (!(en > 1e-12)) {  // d on the axis: any perpendicular direction
    e = axis.unitOrthogonal();
  } else {
    e /= en;
  }
  const double theta = angle_between(d, axis), h = 1e-5;
  const Vec3 d0 = std::cos(theta - h) * axis + std::sin(theta - h) * e;
  const Vec3 d1 = std::cos(theta + h) * axis + std::sin(theta + h) * e;
  return (lens.project(d1) - lens.project(d0)).norm() / (2 * h);
}

std::vector<Vec2> cone_outline(const BallCone& cone, const LensModel& lens, int n) {
  const Vec3 u = cone.axis.unitOrthogonal(), v = cone.axis.cross(u);
  std::vector<Vec2> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * kPi * i / n;
    const Vec3 e = std::cos(phi) * u + std::sin(phi) * v;
    out.push_back(lens.project(std::cos(cone.half_angle) * cone.axis + std::sin(cone.half_angle) * e));
  }
  return out;
}

namespace {

std::vector<double> pixel_scales(const LensModel& lens, const Vec3& axis, const std::vector<Vec3>& rays) {
  std::vector<double> s(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) s[i] = pixels_per_radian(lens, axis, rays[i]);
  return s;
}

}  // namespace

ConeFit fit_cone(const std::vector<Vec3>& rays, const LensModel& lens, const ConeFitOptions& options) {
  const int n = static_cast<int>(rays.size());
  if (n < 3) throw std::invalid_argument("ball outline: " + std::to_string(n) + " points, need at least 3");
  std::optional<BallCone> start = fit_cone_algebraic(rays);
  if (!start) throw std::invalid_argument("ball outline: the points do not lie on a cone in front of the camera");
  std::vector<double> s = pixel_scales(lens, start->axis, rays);

  // RANSAC: the 3-ray cone with the most rays within inlier_px (scales from the all-ray fit).
  // Ray m is an inlier of the cone (a, alpha) when |theta_m - alpha| < delta_m = inlier_px / s_m,
  // i.e. cos(alpha + delta_m) < d_m.a < cos(alpha - delta_m) (the lower bound only when
  // alpha + delta_m < pi, the upper only when alpha > delta_m): a dot product and the bounds' sums
  // of products per ray and sample, instead of an angle. A ray of scale 0 is always an inlier and
  // one of no finite scale never, as |theta - alpha| s < inlier_px has them.
  if (options.ransac_iterations > 0 && n > 3) {
    std::vector<double> dx(n), dy(n), dz(n), delta(n), cd(n), sd(n);
    for (int m = 0; m < n; ++m) {
      dx[m] = rays[m].x(), dy[m] = rays[m].y(), dz[m] = rays[m].z();
      if (s[m] == 0)
        delta[m] = kPi;
      else if (!(std::isfinite(s[m]) && s[m] > 0))
        delta[m] = -1;
      else
        delta[m] = options.inlier_px / s[m];
      cd[m] = std::cos(delta[m]), sd[m] = std::sin(delta[m]);
    }
    std::mt19937_64 rng(options.seed);
    std::uniform_int_distribution<int> pick(0, n - 1);
    int best = -1;
    for (int it = 0; it < options.ransac_iterations; ++it) {
      const int i = pick(rng), j = pick(rng), k = pick(rng);
      if (i == j || j == k || i == k) continue;
      const auto c = fit_cone_algebraic({rays[i], rays[j], rays[k]});
      if (!c) continue;
      const double ax = c->axis.x(), ay = c->axis.y(), az = c->axis.z();
      const double ca = std::cos(c->half_angle), sa = std::sin(c->half_angle), alpha = c->half_angle;
      int count = 0;
      for (int m = 0; m < n; ++m) {
        const double dot = dx[m] * ax + dy[m] * ay + dz[m] * az;
        const double lo = alpha + delta[m] < kPi ? ca * cd[m] - sa * sd[m] : -2.0;
        const double hi = alpha > delta[m] ? ca * cd[m] + sa * sd[m] : 2.0;
        count += delta[m] >= 0 && dot > lo && dot < hi;
      }
      if (count > best) {
        best = count;
        start = c;
      }
    }
  }

  // Gauss-Newton on (tangent rotation of the axis, alpha), Huber weights on pixel residuals:
  //   r_i = (theta_i - alpha) s_i,  theta_i = angle(d_i, a);  for a -> normalize(a + x t1 + y t2)
  //   d theta_i = -(d_i . t) / sin(theta_i) per unit step along t, d r_i / d alpha = -s_i.
  BallCone cone = *start;
  // Outliers of the start (beyond 4 inlier thresholds) are dropped before the robust refinement.
  std::vector<char> use(n, 1);
  for (int m = 0; m < n; ++m) use[m] = std::abs(cone_residual(cone, rays[m])) * s[m] < 4 * options.inlier_px;
  for (int it = 0; it < options.refine_iterations; ++it) {
    s = pixel_scales(lens, cone.axis, rays);
    const Vec3 t1 = cone.axis.unitOrthogonal(), t2 = cone.axis.cross(t1);
    Mat3 jtj = Mat3::Zero();
    Vec3 jtr = Vec3::Zero();
    for (int m = 0; m < n; ++m) {
      if (!use[m]) continue;
      const double theta = angle_between(rays[m], cone.axis);
      const double r = (theta - cone.half_angle) * s[m];
      const double w = std::abs(r) <= options.huber_px ? 1.0 : options.huber_px / std::abs(r);
      const double st = std::max(std::sin(theta), 1e-12);
      const Vec3 j(-rays[m].dot(t1) / st * s[m], -rays[m].dot(t2) / st * s[m], -s[m]);
      jtj += w * j * j.transpose();
      jtr += w * j * r;
    }
    const Vec3 step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) break;
    cone.axis = (cone.axis + step(0) * t1 + step(1) * t2).normalized();
    cone.half_angle = std::clamp(cone.half_angle + step(2), 1e-9, kPi / 2 - 1e-9);
    if (step.norm() < 1e-12) break;
  }

  ConeFit fit;
  fit.cone = cone;
  s = pixel_scales(lens, cone.axis, rays);
  fit.residual_px.resize(n);
  double sum2 = 0;
  for (int m = 0; m < n; ++m) {
    fit.residual_px[m] = cone_residual(cone, rays[m]) * s[m];
    if (std::abs(fit.residual_px[m]) < options.inlier_px) {
      ++fit.inliers;
      sum2 += fit.residual_px[m] * fit.residual_px[m];
    }
  }
  if (fit.inliers < 3) throw std::invalid_argument("ball outline: fewer than 3 points agree on one ball");
  fit.rms_px = std::sqrt(sum2 / fit.inliers);
  return fit;
}

ConeCircle cone_circle(const BallCone& cone, const LensModel& lens) {
  ConeCircle c;
  c.centre_px = lens.project(cone.axis);
  const std::vector<Vec2> outline = cone_outline(cone, lens, 64);
  double sum = 0;
  for (const Vec2& q : outline) sum += (q - c.centre_px).norm();
  c.radius_px = sum / double(outline.size());
  return c;
}

}  // namespace rsibr
