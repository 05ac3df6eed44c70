// Files shared by the rendering verbs (rsibr reference, rsibr render): the environment input with
// its NaN/Inf policy, and the RGBA float32 EXR of a rendered frame with its camera in the header.
#pragma once

#include "core/camera.h"
#include "core/env_map.h"

#include <opencv2/core.hpp>

#include <map>
#include <string>

namespace rsibr::cli {

// Reads an environment (layout: a --layout value or empty). NaN, Inf or absurd values
// (core/texel_audit.h) are an error naming the file, the counts and the first texel unless
// `sanitize`, which zeroes them. Negative values (lossy-compression ringing) are always folded
// into their positive neighbours (remove_negative_ringing: the integral kept), with a warning
// line on stderr giving the count and the integral's change.
EnvMap read_environment_input(const std::string& path, const std::string& layout, bool sanitize);

// rgba: CV_32FC4 (R, G, B, A). ZIP, Rec.709 chromaticities, the camera as rsibr.eye (V3f),
// rsibr.worldFromCam (M33f, columns camera x right, y down, z forward in world) and
// rsibr.intrinsics (M33f, [fx 0 cx; 0 fy cy; 0 0 1], mrcal's pixel convention), plus
// rsibr.<key> string and int attributes (names under 32 characters). Written atomically; errors
// name the file.
void write_render_exr(const std::string& path, const cv::Mat& rgba, const Camera& camera,
                      const std::map<std::string, std::string>& strings, const std::map<std::string, int>& ints = {});

}  // namespace rsibr::cli
