#include "calib/orientation/orientation_solve.h"

#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Dense>

#include <algorithm>
#include <limits>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

namespace rsibr {

namespace {

// Kabsch: the rotation R minimising sum |R a_i - b_i|^2.
Mat3 kabsch(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  Mat3 h = Mat3::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) h += b[i] * a[i].transpose();
  Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 s = Mat3::Identity();
  s(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  return svd.matrixU() * s * svd.matrixV().transpose();
}

}  // namespace

OrientationSolution solve_orientations(int views, int features, const std::vector<DirectionObservation>& obs,
                                       const OrientationOptions& options) {
  if (views < 2) throw OrientationError(-1, std::to_string(views) + " view(s), need at least 2");
  for (const auto& o : obs)
    if (o.view < 0 || o.view >= views || o.feature < 0 || o.feature >= features || !(o.sigma > 0) ||
        !o.direction.allFinite() || std::abs(o.direction.norm() - 1) > 1e-6)
      throw OrientationError(o.view, "invalid observation (feature " + std::to_string(o.feature) + ")");
  std::vector<std::map<int, Vec3>> seen(views);  // per view: feature -> direction
  if (!options.balls.empty()) {
    if (static_cast<int>(options.balls.size()) != views)
      throw OrientationError(-1, "ball priors must be given for every view or none");
    for (const BallPrior& b : options.balls)
      if (!b.axis.allFinite() || std::abs(b.axis.norm() - 1) > 1e-6 || !(b.half_angle > 0 && b.half_angle < kPi / 2) ||
          !(b.sigma_axis > 0) || !std::isfinite(b.sigma_axis) || !(b.sigma_half_angle >= 0) ||
          !std::isfinite(b.sigma_half_angle))
        throw OrientationError(-1, "invalid ball prior");
  }
  for (const auto& o : obs) seen[o.view][o.feature] = o.direction;
  const bool fixed = !options.fixed_world_from_cam.empty();
  if (fixed && static_cast<int>(options.fixed_world_from_cam.size()) != views)
    throw OrientationError(-1, "fixed rotations must be given for every view or none");

  // Start: place views one by one against the world directions known so far (view 0 is the gauge).
  std::vector<Mat3> r(views, Mat3::Identity());
  std::vector<char> placed(views, 0);
  r[0] = options.first_world_from_cam;
  placed[0] = 1;
  std::vector<Vec3> sum(features, Vec3::Zero());
  auto add_view = [&](int v) {
    for (const auto& [f, o] : seen[v]) sum[f] += r[v] * o;
  };
  add_view(0);
  if (fixed) {
    r = options.fixed_world_from_cam;
    std::fill(sum.begin(), sum.end(), Vec3::Zero());
    for (int v = 0; v < views; ++v) placed[v] = 1, add_view(v);
  }
  std::mt19937_64 rng(options.seed);
  const double cos_in = std::cos(options.inlier_deg * kPi / 180);
  std::vector<char> dropped(views, 0);
  std::vector<std::string> left_out(views);
  for (int round = 1; round < views && !fixed; ++round) {
    // The unplaced view sharing the most features with the placed ones.
    int best_v = -1;
    std::vector<int> best_shared;
    for (int v = 0; v < views; ++v) {
      if (placed[v] || dropped[v]) continue;
      std::vector<int> shared;
      for (const auto& [f, o] : seen[v])
        if (sum[f].squaredNorm() > 0) shared.push_back(f);
      if (best_v < 0 || shared.size() > best_shared.size()) best_v = v, best_shared = shared;
    }
    if (best_v < 0) break;
    if (best_shared.size() < 3) {
      if (!options.leave_out_unplaced)
        throw OrientationError(best_v, "shares " + std::to_string(best_shared.size()) +
                                           " feature(s) with the other views; need at least 3 to orient it");
      // The view sharing the most cannot be placed: neither can the rest.
      for (int v = 0; v < views; ++v)
        if (!placed[v] && !dropped[v]) {
          dropped[v] = 1;
          left_out[v] = "shares fewer than 3 features with the oriented views";
        }
      break;
    }
    const int v = best_v;
    std::vector<Vec3> a, b;
    for (int f : best_shared) a.push_back(seen[v].at(f)), b.push_back(sum[f].normalized());
    std::uniform_int_distribution<int> pick(0, static_cast<int>(a.size()) - 1);
    std::vector<int> best_in;
    for (int it = 0; it < options.ransac_iterations; ++it) {
      const int i = pick(rng), j = pick(rng);
      if (i == j || a[i].cross(a[j]).norm() < 1e-3) continue;
      const Mat3 rr = kabsch({a[i], a[j]}, {b[i], b[j]});
      std::vector<int> in;
      for (int k = 0; k < static_cast<int>(a.size()); ++k)
        if ((rr * a[k]).dot(b[k]) > cos_in) in.push_back(k);
      if (in.size() > best_in.size()) best_in = in;
    }
    if (best_in.size() < 3) {
      const std::string why = "no rotation agrees with 3 or more shared features";
      if (!options.leave_out_unplaced) throw OrientationError(v, why);
      dropped[v] = 1;
      left_out[v] = why;
      continue;
    }
    std::vector<Vec3> ai, bi;
    for (int k : best_in) ai.push_back(a[k]), bi.push_back(b[k]);
    r[v] = kabsch(ai, bi);
    placed[v] = 1;
    add_view(v);
  }

  // The joint problem.
  std::vector<Eigen::Quaterniond> q(views);
  for (int v = 0; v < views; ++v) q[v] = Eigen::Quaterniond(r[v]).normalized();
  std::vector<Vec3> d(features, Vec3::Zero());
  for (int f = 0; f < features; ++f)
    if (sum[f].squaredNorm() > 0) d[f] = sum[f].normalized();
  ceres::Problem problem;
  const bool refine_balls = !options.balls.empty();
  std::vector<Vec3> axes;
  std::vector<double> sines;
  for (const BallPrior& b : options.balls) axes.push_back(b.axis), sines.push_back(std::sin(b.half_angle));
  for (const auto& o : obs) {
    if (dropped[o.view]) continue;
    if (refine_balls && o.ray.squaredNorm() > 0) {
      auto* cost = new ceres::AutoDiffCostFunction<BallReflectionResidual, 3, 4, 3, 1, 3>(
          new BallReflectionResidual(o.ray.normalized(), o.sigma));
      problem.AddResidualBlock(cost, new ceres::CauchyLoss(options.loss_sigmas), q[o.view].coeffs().data(),
                               axes[o.view].data(), &sines[o.view], d[o.feature].data());
      continue;
    }
    auto* cost =
        new ceres::AutoDiffCostFunction<DirectionResidual, 3, 4, 3>(new DirectionResidual(o.direction, o.sigma));
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(options.loss_sigmas), q[o.view].coeffs().data(),
                             d[o.feature].data());
  }
  for (int v = 0; v < views && refine_balls; ++v) {
    if (!problem.HasParameterBlock(axes[v].data())) continue;
    const BallPrior& b = options.balls[v];
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BallAxisPrior, 3, 3>(new BallAxisPrior(b.axis, b.sigma_axis)), nullptr,
        axes[v].data());
    problem.SetManifold(axes[v].data(), new ceres::SphereManifold<3>);
    if (b.sigma_half_angle > 0) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<HalfAnglePrior, 1, 1>(new HalfAnglePrior(b.half_angle, b.sigma_half_angle)),
          nullptr, &sines[v]);
      problem.SetParameterLowerBound(&sines[v], 0, 1e-6);
      problem.SetParameterUpperBound(&sines[v], 0, 1 - 1e-6);
    } else {
      problem.SetParameterBlockConstant(&sines[v]);
    }
  }
  for (int v = 0; v < views; ++v)
    if (problem.HasParameterBlock(q[v].coeffs().data()))
      problem.SetManifold(q[v].coeffs().data(), new ceres::EigenQuaternionManifold);
  for (int f = 0; f < features; ++f)
    if (problem.HasParameterBlock(d[f].data())) problem.SetManifold(d[f].data(), new ceres::SphereManifold<3>);
  for (int v = 0; v < (fixed ? views : 1); ++v)
    if (problem.HasParameterBlock(q[v].coeffs().data())) problem.SetParameterBlockConstant(q[v].coeffs().data());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_SCHUR;
  so.max_num_iterations = 100;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;  // deterministic
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw std::runtime_error("orientation: Ceres failed: " + summary.message);

  OrientationSolution out;
  for (int v = 0; v < views; ++v) out.oriented.push_back(dropped[v] ? 0 : 1);
  out.left_out = left_out;
  out.world_from_cam.resize(views);
  for (int v = 0; v < views; ++v) out.world_from_cam[v] = q[v].normalized().toRotationMatrix();
  out.feature_directions = d;
  for (Vec3& a : axes) a.normalize();
  out.ball_axes = axes;
  for (double sv : sines) out.ball_half_angles.push_back(std::asin(sv));
  double sum2 = 0;
  for (const auto& o : obs) {
    if (dropped[o.view]) continue;
    const Vec3 dir = refine_balls && o.ray.squaredNorm() > 0
                         ? reflect_off_ball<double>(o.ray.normalized(), axes[o.view], sines[o.view]).normalized()
                         : o.direction;
    const double e2 = (out.world_from_cam[o.view] * dir - d[o.feature]).squaredNorm() / (o.sigma * o.sigma);
    ++out.observations;
    if (e2 < options.loss_sigmas * options.loss_sigmas) sum2 += e2, ++out.inliers;
  }
  out.rms_sigmas = out.inliers ? std::sqrt(sum2 / out.inliers) : 0;

  out.sigma_deg.assign(views, 0.0);
  if (fixed) return out;
  // Covariance of each free view's rotation, in the manifold's tangent space (3 x 3).
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::SPARSE_QR;
  co.num_threads = 1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (int v = 1; v < views; ++v)
    if (!dropped[v]) blocks.emplace_back(q[v].coeffs().data(), q[v].coeffs().data());
  if (cov.Compute(blocks, &problem)) {
    for (int v = 1; v < views; ++v) {
      if (dropped[v]) continue;
      double c[9];  // 3 x 3, row-major
      cov.GetCovarianceBlockInTangentSpace(q[v].coeffs().data(), q[v].coeffs().data(), c);
      out.sigma_deg[v] = 2 * std::sqrt(std::max(0.0, c[0] + c[4] + c[8])) * 180 / kPi;
    }
  } else {
    for (int v = 1; v < views; ++v)
      if (!dropped[v]) out.sigma_deg[v] = std::numeric_limits<double>::infinity();
  }
  return out;
}

}  // namespace rsibr
