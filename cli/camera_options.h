// The camera options shared by the rendering verbs (rsibr reference, rsibr render):
//   --size WxH  --fov DEG  --eye x,y,z  --at x,y,z  --up x,y,z  --from x,y,z  --turntable N
// Without --eye the camera frames the mesh's bounding sphere (90% of the smaller field of view),
// looking from direction --from (world, from the object toward the camera; default 0,0.3,1), with --at
// defaulting to the bounds' centre. --turntable N orbits the camera about --up through --at in N
// equal steps (frame k of N).
#pragma once

#include "core/camera.h"

#include <CLI/CLI.hpp>

#include <string>

namespace rsibr::cli {

// More frames than this is a typo (each frame is a file).
inline constexpr int kMaxTurntableFrames = 100000;

struct CameraArgs {
  std::string size = "1280x720";
  double fov = 40;
  std::string eye, at, up = "0,1,0", from = "0,0.3,1";
  int turntable = 0;  // 0 = one frame
};

void add_camera_options(CLI::App* verb, CameraArgs& args);

// Frame k (of max(1, turntable)) for a mesh with these bounds. Throws std::invalid_argument with the
// option's name for bad values.
Camera make_camera(const CameraArgs& args, const Eigen::AlignedBox3f& bounds, int k = 0);

// "frame.png" with turntable N > 0 -> "frame.0007.png" (4 digits, or more when N needs them);
// unchanged when turntable is 0.
std::string frame_path(const std::string& output, int turntable, int k);

}  // namespace rsibr::cli
