// Camera poses around the ball rig from the named view plans of a scene spec:
//
//   ring      `count` views evenly spaced in azimuth (or explicit `azimuths_deg`) at one elevation
//   icosa     the icosahedron's 12 vertex directions (core/view_set.h), those below
//             `min_elevation_deg` dropped
//   handheld  a ring whose positions (std dev `jitter_m` per axis) and orientations (a rotation of
//             std dev `jitter_deg` about a random axis) are jittered, seeded
//
// Azimuth 0 is +Z, 90 is +X; elevation is above the horizontal plane through look_at. Cameras look
// at look_at (default: the rig centre) with world +Y up in the image, turn right by pan_deg about the
// world's vertical and by yaw_deg about their own y axis (the target moves toward the left edge),
// then roll about their axis.
#pragma once

#include "capture/synth_scene.h"
#include "core/camera.h"

#include <string>
#include <vector>

namespace rsibr {

// Every plan's poses in order, named view00, view01, ... Same scene and seed, same poses.
std::vector<CameraPose> plan_camera_poses(const SynthScene& scene);

}  // namespace rsibr
