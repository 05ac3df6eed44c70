// The views' orientations as a file (poses.yaml), written by `rsibr orient` and read by
// `rsibr extract --poses` and `rsibr process`:
//
//   rsibr_poses: 1
//   gauge: first-view            # "up" or "estimated-up": how the world frame was fixed (calib/orientation/view_orientation.h)
//   views:
//     - {name: north, world_from_cam: [9 numbers, row-major], sigma_deg: 0.03,
//        ball: {axis: [x, y, z], half_angle_deg: 5.7}}     # optional
//
// world_from_cam: columns = the camera's x (right), y (down), z (forward) axes in the world frame;
// a proper rotation (checked to 1e-6, then re-orthonormalised). sigma_deg: the orientation's std
// dev in degrees, all axes together (0 for the gauge view when the gauge is "first-view"). ball: the
// chrome ball's cone (calib/balls/ball_cone.h; axis unit in the camera frame, half angle in (0, 90)
// degrees) as refined with the orientations, which is nearer the truth than the outline's (the
// outline lies inside a mirror ball's limb); extraction uses it for the chrome ball.
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/vec.h"

#include <optional>

#include <string>
#include <vector>

namespace rsibr {

struct ViewPose {
  std::string name;
  Mat3 world_from_cam = Mat3::Identity();
  double sigma_deg = 0;
  std::optional<BallCone> ball;  // the chrome ball refined by the orientation solve, when known
};

struct PoseSet {
  std::string gauge = "first-view";  // "first-view", "up" or "estimated-up" (+Y up in both)
  std::vector<ViewPose> views;

  // The view named `name`, or nullptr.
  const ViewPose* find(const std::string& name) const;
};

// Strict (formats/yaml_spec.h): unknown keys, missing keys, duplicate names, a matrix that is not a
// rotation, a negative or non-finite sigma are errors. Throws std::invalid_argument("<path>: <problem>").
PoseSet read_pose_file(const std::string& path);

// Atomic (formats/atomic_file.h); rotations with 17 significant digits (a round trip is exact to
// rounding), sigma_deg with 6.
// Throws std::invalid_argument for an invalid set (the same checks as reading).
void write_pose_file(const std::string& path, const PoseSet& poses);

}  // namespace rsibr
