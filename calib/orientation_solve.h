// Camera orientations from directions seen in the chrome ball: each view v observes features f as
// unit directions o_vf in its camera frame (the reflected ray of a feature inside the ball, turned
// into a direction at infinity with the exact per-pixel geometry); the world directions d_f and the
// rotations world_from_cam R_v are solved together:
//
//   minimise  sum_vf rho( |(R_v o_vf - d_f) / sigma_vf|^2 )
//
// R_v as Eigen quaternions (ceres::EigenQuaternionManifold, (x,y,z,w)), d_f on
// ceres::SphereManifold<3>, residuals whitened by each observation's angular std dev sigma (radians;
// |R o - d| is the chord, = the angle to second order), rho a Cauchy loss of scale `loss_sigmas`.
// Gauge: the first view's rotation is held at its given value (identity by default).
// Start: per view, a rotation RANSAC over pairs of features shared with the views already placed
// (2-point Kabsch; inliers within inlier_deg), refined by Kabsch over the inliers; each d_f starts at
// the mean of its placed observations. ceres::Covariance gives each view's rotation covariance in the
// manifold's tangent space; EigenQuaternionManifold's tangent delta rotates by 2 |delta|, so the
// rotation's std dev is 2 sqrt(trace(C)) (all three axes together), reported in degrees.
#pragma once

#include "core/vec.h"

#include <cstdint>
#include <string>
#include <vector>

namespace rsibr {

struct DirectionObservation {
  int view = 0, feature = 0;
  Vec3 direction;     // unit, camera frame of `view`
  double sigma = 0;   // angular std dev, radians (> 0)
};

struct OrientationOptions {
  double loss_sigmas = 3.0;      // Cauchy loss scale, in sigmas
  double inlier_deg = 2.0;       // RANSAC inlier threshold
  int ransac_iterations = 200;
  std::uint64_t seed = 1;
  Mat3 first_world_from_cam = Mat3::Identity();  // the gauge
};

struct OrientationSolution {
  std::vector<Mat3> world_from_cam;     // per view
  std::vector<double> sigma_deg;        // per view: rotation std dev, all axes together (0 for the gauge view)
  std::vector<Vec3> feature_directions; // per feature, world, unit (zero for unobserved features)
  double rms_sigmas = 0;                // RMS whitened residual over inliers
  int inliers = 0, observations = 0;
};

// Cost of one observation (exposed for its gradient check): residual (R(q) o - d) / sigma, 3 values.
struct DirectionResidual {
  DirectionResidual(const Vec3& o, double sigma) : o_(o), inv_sigma_(1.0 / sigma) {}
  template <class T>
  bool operator()(const T* q, const T* d, T* r) const {  // q: x, y, z, w; d: 3
    const Eigen::Map<const Eigen::Quaternion<T>> rot(q);
    const Eigen::Matrix<T, 3, 1> ro = rot * o_.cast<T>();
    for (int k = 0; k < 3; ++k) r[k] = (ro[k] - d[k]) * T(inv_sigma_);
    return true;
  }
  Vec3 o_;
  double inv_sigma_;
};

// Throws std::invalid_argument("orientation: ...") for fewer than two views, a view that shares fewer
// than 3 features with the others (nothing ties it down) or invalid observations.
OrientationSolution solve_orientations(int views, int features, const std::vector<DirectionObservation>& observations,
                                       const OrientationOptions& options = {});

}  // namespace rsibr
