#include "calib/orientation/world_up.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {

struct Solve {
  Vec3 u;
  Eigen::Matrix2d information;
};

Solve gauss_newton(const std::vector<Vec3>& x, const std::vector<double>& weight, double sigma_roll,
                   const std::vector<VerticalLine>& lines, const std::vector<double>& line_weight, const Vec3& u0,
                   double sigma_prior, Vec3 u) {
  Eigen::Matrix2d jtj = Eigen::Matrix2d::Identity();
  for (int it = 0; it < 20; ++it) {
    const Vec3 t1 = u.unitOrthogonal(), t2 = u.cross(t1);
    jtj.setZero();
    Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
    auto add = [&](const Vec3& a, double sigma, double r, double w = 1) {  // residual r = a . u / sigma (linearised)
      const Eigen::Vector2d j(a.dot(t1) / sigma, a.dot(t2) / sigma);
      jtj += w * j * j.transpose();
      jtr += w * j * r;
    };
    for (std::size_t i = 0; i < x.size(); ++i) add(x[i], sigma_roll, x[i].dot(u) / sigma_roll, weight[i]);
    for (std::size_t j = 0; j < lines.size(); ++j) {
      const double s = lines[j].sigma_deg * kDeg;
      add(lines[j].plane_normal, s, lines[j].plane_normal.dot(u) / s, line_weight[j]);
    }
    // Prior on the tangent components of u - u0.
    const Vec3 d = u - u0;
    add(t1, sigma_prior, d.dot(t1) / sigma_prior);
    add(t2, sigma_prior, d.dot(t2) / sigma_prior);
    const Eigen::Vector2d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) break;
    u = (u + step[0] * t1 + step[1] * t2).normalized();
    if (step.norm() < 1e-13) break;
  }
  return {u, jtj};
}

}  // namespace

WorldUp estimate_world_up(const std::vector<Mat3>& world_from_cam, const std::vector<VerticalLine>& lines,
                          const WorldUpOptions& o) {
  if (world_from_cam.empty()) throw std::invalid_argument("world up: no cameras");
  std::vector<Vec3> x;
  Vec3 u0 = Vec3::Zero();
  for (const Mat3& r : world_from_cam) {
    if (!r.allFinite()) throw std::invalid_argument("world up: a non-finite rotation");
    x.push_back(r.col(0).normalized());
    u0 -= r.col(1).normalized();
  }
  if (!(u0.norm() > 1e-9)) u0 = -world_from_cam.front().col(1);
  u0.normalize();
  // Start: the smallest eigenvector of the cue scatter, signed toward the upright prior.
  double sigma_roll = o.roll_sigma_deg * kDeg;
  Mat3 s = Mat3::Zero();
  for (const Vec3& xi : x) s += xi * xi.transpose() / (sigma_roll * sigma_roll);
  for (const VerticalLine& l : lines)
    s += l.plane_normal * l.plane_normal.transpose() / std::pow(l.sigma_deg * kDeg, 2);
  s += (Mat3::Identity() - u0 * u0.transpose()) / std::pow(o.prior_sigma_deg * kDeg, 2);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(s);
  Vec3 start = eig.eigenvectors().col(0);
  if (start.dot(u0) < 0) start = -start;
  const double sigma_prior = o.prior_sigma_deg * kDeg;
  std::vector<double> weight(x.size(), 1.0), line_weight(lines.size(), 1.0);
  Solve sol = gauss_newton(x, weight, sigma_roll, lines, line_weight, u0, sigma_prior, start);
  WorldUp out;
  if (x.size() >= 4) {
    // The roll scatter from the residuals (robustly: 1.4826 MAD), and Cauchy weights at 2.5 of it,
    // so that a camera turned about its own tilted axis (its x out of the horizontal) does not pull
    // the level of the others; repeated as the residuals settle.
    for (int it = 0; it < 6; ++it) {
      std::vector<double> a;
      for (const Vec3& xi : x) a.push_back(std::abs(std::asin(std::clamp(xi.dot(sol.u), -1.0, 1.0))));
      std::vector<double> sorted = a;
      std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
      // MAD about zero of n - 2 free residuals: scaled so that a Gaussian scatter gives its sigma.
      const double mad = 1.4826 * sorted[sorted.size() / 2] * std::sqrt(double(x.size()) / double(x.size() - 2));
      sigma_roll = std::max(mad, o.min_roll_sigma_deg * kDeg);
      for (std::size_t i = 0; i < x.size(); ++i) weight[i] = 1 / (1 + std::pow(a[i] / (2.5 * sigma_roll), 2));
      for (std::size_t j = 0; j < lines.size(); ++j)
        line_weight[j] = 1 / (1 + std::pow(lines[j].plane_normal.dot(sol.u) / (3 * lines[j].sigma_deg * kDeg), 2));
      sol = gauss_newton(x, weight, sigma_roll, lines, line_weight, u0, sigma_prior, sol.u);
    }
    out.roll_sigma_estimated = true;
  } else if (!lines.empty()) {
    for (int it = 0; it < 4; ++it) {
      for (std::size_t j = 0; j < lines.size(); ++j)
        line_weight[j] = 1 / (1 + std::pow(lines[j].plane_normal.dot(sol.u) / (3 * lines[j].sigma_deg * kDeg), 2));
      sol = gauss_newton(x, weight, sigma_roll, lines, line_weight, u0, sigma_prior, sol.u);
    }
  }
  out.up = sol.u;
  out.roll_sigma_deg = sigma_roll / kDeg;
  const Eigen::Matrix2d cov = sol.information.inverse();
  out.sigma_deg = std::sqrt(std::max(0.0, cov.trace())) / kDeg;
  for (const Vec3& xi : x) out.roll_deg.push_back(std::asin(std::clamp(xi.dot(sol.u), -1.0, 1.0)) / kDeg);
  out.lines = int(lines.size());
  out.tilt_from_first_deg = angle_between(sol.u, -world_from_cam.front().col(1)) / kDeg;
  return out;
}

}  // namespace rsibr
