// A ball seen by a camera as a cone of rays: the silhouette of a sphere (centre C, radius R) seen
// from the camera centre is the set of unit camera-frame rays d with
//   d . a = cos(alpha),   a = C / |C| (the centre direction),  sin(alpha) = R / |C|.
// Fitting that cone to unprojected outline rays works for any lens (the silhouette is an ellipse
// only for a pinhole, and not even that with distortion), and the ball centre's pixel is
// lens.project(a) exactly, which the centre of a fitted ellipse is not (perspective shifts it).
//
// Frames: camera frame of core/lens_model.h (x right, y down, z forward); angles in radians.
#pragma once

#include "core/lens_model.h"
#include "core/vec.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace rsibr {

struct BallCone {
  Vec3 axis = Vec3(0, 0, 1);  // unit, camera frame: from the camera centre toward the ball centre
  double half_angle = 0;      // alpha, radians, in (0, pi/2)

  // Distance from the camera centre to the ball centre for a ball of radius R: R / sin(alpha).
  double distance(double radius) const { return radius / std::sin(half_angle); }
  // The ball centre in the camera frame (axis * distance).
  Vec3 centre(double radius) const { return axis * distance(radius); }
};

// Signed angle (radians) of a unit ray outside the cone: angle(d, axis) - half_angle.
double cone_residual(const BallCone& cone, const Vec3& ray);

// Algebraic fit: the w minimising sum (d_i . w - 1)^2 gives axis = w/|w|, cos(alpha) = 1/|w|.
// Needs >= 3 rays not all on one great circle; nullopt when the system is singular or the result
// is not a cone in front of the camera (cos(alpha) outside (0,1)).
std::optional<BallCone> fit_cone_algebraic(const std::vector<Vec3>& rays, const std::vector<double>& weights = {});

struct ConeFitOptions {
  int ransac_iterations = 1000;  // minimal (3-ray) samples; 0 skips RANSAC
  double inlier_px = 1.0;        // RANSAC inlier threshold, pixels
  double huber_px = 0.5;         // robust loss scale of the refinement, pixels
  int refine_iterations = 20;    // Gauss-Newton iterations
  std::uint64_t seed = 1;        // RANSAC sampling
};

struct ConeFit {
  BallCone cone;
  int inliers = 0;                  // rays within inlier_px of the fitted outline
  double rms_px = 0;                // RMS pixel residual over the inliers
  std::vector<double> residual_px;  // signed, per ray (outward positive)
};

// Robust fit of the cone to outline rays: RANSAC over 3-ray algebraic fits, then iteratively
// reweighted Gauss-Newton on the residuals in pixels, r_i = (angle(d_i, a) - alpha) * s_i, with
// s_i the lens's pixels per radian across the outline at ray i (the cone's angular residual
// whitened into pixels, so that the fit weighs every outline point like its pixel noise).
// Throws std::invalid_argument when fewer than 3 rays are given or no cone fits them.
ConeFit fit_cone(const std::vector<Vec3>& rays, const LensModel& lens, const ConeFitOptions& options = {});

// Pixels per radian, at the ray d, of a rotation of d away from `axis` (the local scale across
// the outline). Finite-difference through lens.project.
double pixels_per_radian(const LensModel& lens, const Vec3& axis, const Vec3& d);

// The cone's outline as n pixel positions (rays at angle alpha around the axis, projected).
std::vector<Vec2> cone_outline(const BallCone& cone, const LensModel& lens, int n);

// The ball's circle in the image: its centre pixel (lens.project(axis)) and the mean distance of
// its outline (64 points) from it.
struct ConeCircle {
  Vec2 centre_px = Vec2::Zero();
  double radius_px = 0;
};
ConeCircle cone_circle(const BallCone& cone, const LensModel& lens);

}  // namespace rsibr
