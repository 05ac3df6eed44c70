// Camera orientations given to rsibr process --poses, until (or instead of) the orient step's
// solve: the shared poses.yaml format (calib/pose_file.h, written by rsibr orient):
//   rsibr_poses: 1
//   gauge: first-view | up
//   views: [{name: north, world_from_cam: [9 numbers, row-major], sigma_deg: 0.03}]
// or the truth.yaml of rsibr synth (views: [{name, world_from_cam: [[3], [3], [3]]}], sigma 0:
// the exact poses, for tests and for measuring the other stages' errors alone).
// world_from_cam's columns are the camera's x right, y down, z forward in world coordinates.
#pragma once

#include "core/vec.h"

#include <map>
#include <string>

namespace rsibr {

struct GivenPose {
  Mat3 world_from_cam = Mat3::Identity();
  double sigma_deg = 0;
};

struct GivenPoses {
  std::string source;  // "poses.yaml" or "synth truth"
  std::string gauge;   // "first-view", "up" or "truth"
  std::map<std::string, GivenPose> views;
};

// Throws std::invalid_argument("<path>: <problem>") for a missing file, an unknown format, a
// matrix that is not a rotation (|R^T R - I| > 1e-4 or det < 0), or a duplicate view name.
GivenPoses read_given_poses(const std::string& path);

}  // namespace rsibr
