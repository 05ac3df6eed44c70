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

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace rsibr {

// An input the solve cannot use, kept as data: the view it concerns (its index in the solve's
// order; -1 when it concerns none) and the problem; callers name the view in their own terms.
// what() = "orientation: [view <index>: ]<problem>". An std::invalid_argument: the input is at fault.
class OrientationError : public std::invalid_argument {
 public:
  OrientationError(int view, const std::string& problem)
      : std::invalid_argument("orientation: " + (view >= 0 ? "view " + std::to_string(view) + ": " : std::string()) +
                              problem),
        view_(view),
        problem_(problem) {}
  int view() const noexcept { return view_; }
  const std::string& problem() const noexcept { return problem_; }

 private:
  int view_;
  std::string problem_;
};

struct DirectionObservation {
  int view = 0, feature = 0;
  Vec3 direction;    // unit, camera frame of `view`
  double sigma = 0;  // angular std dev, radians (> 0)
  // The unit camera ray of the feature's pixel (lens.unproject), or zero. With a ball prior for the
  // view (OrientationOptions::balls) the direction is recomputed from it and the view's ball axis in
  // the solve (BallReflectionResidual), so the ball centre is refined by the features.
  Vec3 ray = Vec3::Zero();
  int index = -1;  // the feature's index among its view's detections (calib/orientation/ball_features.h), or -1
};

// A view's ball as located in its image (calib/balls/ball_cone.h), with the std dev of its axis
// (radians, per tangent axis): the prior of the joint refinement.
struct BallPrior {
  Vec3 axis = Vec3(0, 0, 1);
  double half_angle = 0;
  double sigma_axis = 0;        // > 0
  double sigma_half_angle = 0;  // radians; > 0: the half angle is refined too, with this prior; 0: held
};

struct OrientationOptions {
  double loss_sigmas = 3.0;  // Cauchy loss scale, in sigmas
  double inlier_deg = 2.0;   // RANSAC inlier threshold
  int ransac_iterations = 200;
  std::uint64_t seed = 1;
  Mat3 first_world_from_cam = Mat3::Identity();  // the gauge
  // Per view, or empty: each view's ball axis a_v joins the problem (ceres::SphereManifold<3>) with
  // the prior residual (a_v - axis) / sigma_axis, and observations with a ray use
  // BallReflectionResidual. The half angle's sine s_v joins too where sigma_half_angle > 0 (prior
  // (s_v - sin half_angle) / (sigma_half_angle cos half_angle)): an outline found a pixel inside the
  // limb scales the rim's directions radially, which no rotation absorbs.
  std::vector<BallPrior> balls;
  // Per view, or empty: the rotations are known (a pose file) and held at these; the solve then
  // refines only the feature directions and, with `balls`, the balls (sigma_deg is 0 for every view).
  std::vector<Mat3> fixed_world_from_cam;
  // A view that cannot be placed (fewer than 3 features shared with the placed views, or no
  // rotation agreeing with 3) is left out (OrientationSolution::oriented) instead of an error.
  bool leave_out_unplaced = false;
};

struct OrientationSolution {
  std::vector<char> oriented;            // per view: 1, or 0 when left out (leave_out_unplaced)
  std::vector<std::string> left_out;     // per view: why it was left out ("" when oriented)
  std::vector<Mat3> world_from_cam;      // per view (identity for a view left out)
  std::vector<double> sigma_deg;         // per view: rotation std dev, all axes together (0 for the gauge view)
  std::vector<Vec3> feature_directions;  // per feature, world, unit (zero for unobserved features)
  std::vector<Vec3> ball_axes;           // per view, the refined ball axes (camera frame; with balls only)
  std::vector<double> ball_half_angles;  // per view, the refined half angles (radians; with balls only)
  double rms_sigmas = 0;                 // RMS whitened residual over inliers
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

// The reflected direction (camera frame, unit) of the camera ray `ray` (unit) off a ball of radius 1
// centred at C = axis / sin(alpha) (axis unit): the ray meets the sphere first at P = t ray,
// t = b - sqrt(b^2 - (|C|^2 - 1)), b = ray . C; n = P - C; r = ray - 2 (ray . n) n. A ray that misses
// the ball (b^2 < |C|^2 - 1) is clamped to the tangent point (the discriminant to 0).
template <class T, class S>
Eigen::Matrix<T, 3, 1> reflect_off_ball(const Eigen::Matrix<T, 3, 1>& ray, const Eigen::Matrix<T, 3, 1>& axis,
                                        const S& sin_alpha) {
  using std::sqrt;
  const Eigen::Matrix<T, 3, 1> c = axis / (axis.norm() * T(sin_alpha));
  const T b = ray.dot(c);
  T disc = b * b - (c.squaredNorm() - T(1));
  if (disc < T(1e-12)) disc = T(1e-12);
  const Eigen::Matrix<T, 3, 1> n = (b - sqrt(disc)) * ray - c;
  return ray - T(2) * ray.dot(n) * n;
}

// Cost of one observation with its view's ball refined: (R(q) reflect_off_ball(ray, a, s) - d) / sigma,
// s the sine of the ball's half angle.
struct BallReflectionResidual {
  BallReflectionResidual(const Vec3& ray, double sigma) : ray_(ray), inv_sigma_(1.0 / sigma) {}
  template <class T>
  bool operator()(const T* q, const T* a, const T* s, const T* d, T* r) const {  // q: x, y, z, w; a: 3; s: 1; d: 3
    const Eigen::Map<const Eigen::Quaternion<T>> rot(q);
    const Eigen::Matrix<T, 3, 1> o =
        reflect_off_ball<T>(ray_.cast<T>(), Eigen::Matrix<T, 3, 1>(a[0], a[1], a[2]), s[0]);
    const Eigen::Matrix<T, 3, 1> ro = rot * o;
    for (int k = 0; k < 3; ++k) r[k] = (ro[k] - d[k]) * T(inv_sigma_);
    return true;
  }
  Vec3 ray_;
  double inv_sigma_;
};

// The ball axis prior: (a - axis0) / sigma, 3 values (the chord, = the angle to second order).
struct BallAxisPrior {
  BallAxisPrior(const Vec3& axis, double sigma) : axis_(axis), inv_sigma_(1.0 / sigma) {}
  template <class T>
  bool operator()(const T* a, T* r) const {
    for (int k = 0; k < 3; ++k) r[k] = (a[k] - T(axis_[k])) * T(inv_sigma_);
    return true;
  }
  Vec3 axis_;
  double inv_sigma_;
};

// The half angle prior: (s - sin alpha0) / (sigma cos alpha0), 1 value (the angle to first order).
struct HalfAnglePrior {
  HalfAnglePrior(double alpha, double sigma) : s0_(std::sin(alpha)), inv_sigma_(1.0 / (sigma * std::cos(alpha))) {}
  template <class T>
  bool operator()(const T* s, T* r) const {
    r[0] = (s[0] - T(s0_)) * T(inv_sigma_);
    return true;
  }
  double s0_, inv_sigma_;
};

// Throws std::invalid_argument("orientation: ...") for fewer than two views, a view that shares fewer
// than 3 features with the others (nothing ties it down) or invalid observations.
OrientationSolution solve_orientations(int views, int features, const std::vector<DirectionObservation>& observations,
                                       const OrientationOptions& options = {});

}  // namespace rsibr
