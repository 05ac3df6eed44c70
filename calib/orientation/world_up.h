// The world's up from the views themselves, for a level world without a level camera. Handheld
// cameras are aimed down at the rig (so a camera's -y is not up), but people hold them level in
// roll: each camera's x axis (right) is nearly horizontal. Up is then the direction most
// perpendicular to every camera's x axis; a vertical line seen in a view (the stand under a ball)
// adds that its plane through the camera centre contains up.
//
//   minimise over unit u:  sum_i (x_i . u / sigma_roll)^2 + sum_j (m_j . u / sigma_j)^2
//                          + |u - u0|_tangent^2 / sigma_prior^2
//
// x_i = world_from_cam_i * (1, 0, 0); m_j the unit normals of the vertical lines' planes (world);
// u0 = the cameras' mean -y axis (upright cameras), a weak prior (sigma_prior) that only decides
// what the cameras cannot: with every x axis parallel (all views from one side) the tilt about that
// axis. Start: the eigenvector of sum x_i x_i^T / sigma_roll^2 + sum m_j m_j^T / sigma_j^2 with
// the smallest eigenvalue, signed toward u0; then Gauss-Newton on u's tangent plane. sigma_roll is
// the cameras' roll scatter: with at least 4 cameras, 1.4826 times the median |asin(x_i . u)|
// (scaled for the n - 2 degrees of freedom), never below `min_roll_sigma_deg`, and each camera
// weighted by a Cauchy loss at 2.5 sigma_roll (a camera turned about its own tilted axis, its x
// out of the horizontal, does not pull the others); else `roll_sigma_deg`, unweighted. Lines are
// Cauchy-weighted at 3 of their own sigmas (a line that is not vertical gives way). The std dev
// of u (degrees, both tangent axes together) is from the inverse of the weighted normal equations.
// Frames: whatever frame the rotations are in (the orientation solve's), u in that frame.
#pragma once

#include "core/vec.h"

#include <string>
#include <vector>

namespace rsibr {

struct WorldUpOptions {
  double roll_sigma_deg = 1.0;      // assumed roll scatter with fewer than 4 cameras
  double min_roll_sigma_deg = 0.2;  // floor of the estimated scatter
  double prior_sigma_deg = 20;      // the upright-cameras prior
};

struct VerticalLine {
  Vec3 plane_normal;  // unit, world (the solve's frame): normal of the plane through the camera centre and the line
  double sigma_deg = 0.3;  // how well the line fixes it
  std::string what;        // e.g. "view03: stand under chrome"
};

struct WorldUp {
  Vec3 up = Vec3(0, 1, 0);    // unit
  double sigma_deg = 0;       // std dev, both axes together
  double roll_sigma_deg = 0;  // the cameras' roll scatter used
  bool roll_sigma_estimated = false;
  std::vector<double> roll_deg;  // per camera: asin(x_i . u), its roll from level
  int lines = 0;
  double tilt_from_first_deg = 0;  // angle between u and the first camera's -y axis
};

// `world_from_cam` >= 1 rotation. Throws std::invalid_argument for none or a non-finite one.
WorldUp estimate_world_up(const std::vector<Mat3>& world_from_cam, const std::vector<VerticalLine>& lines = {},
                          const WorldUpOptions& options = {});

}  // namespace rsibr
