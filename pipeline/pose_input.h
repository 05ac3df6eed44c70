// Camera orientations given to rsibr process --poses instead of the orient step's solve: a
// poses.yaml (calib/orientation/pose_file.h, as rsibr orient writes it) or the truth.yaml of rsibr synth
// (views: [{name, world_from_cam: [[3], [3], [3]]}], world +Y up; sigma 0: the exact poses, for
// tests and for measuring the other stages' errors alone).
#pragma once

#include "calib/orientation/pose_file.h"

#include <string>

namespace rsibr {

// Throws std::invalid_argument("<path>: <problem>") for a missing file, an unknown format, a
// matrix that is not a rotation (|R^T R - I| > 1e-4 or det < 0), or a duplicate view name.
PoseSet read_given_poses(const std::string& path);

}  // namespace rsibr
