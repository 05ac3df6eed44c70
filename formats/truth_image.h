// Linear images of the truth folder: float32 RGB OpenEXR (scene-linear, Rec.709/D65 chromaticities)
// with provenance in the header: rsibr.* strings, the pose as rsibr.worldFromCam (M33f, columns the
// camera's x right, y down, z forward in world) and rsibr.eye (V3f, world).
#pragma once

#include "core/camera.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <map>
#include <string>

namespace rsibr {

// `rgb` CV_32FC3 (RGB order) or CV_32FC1 (written as Y). Atomic; throws FileError (formats/file_error.h).
void write_truth_image(const std::filesystem::path& path, const cv::Mat& rgb, const CameraPose* pose,
                       const std::map<std::string, std::string>& attributes);
// Reads what write_truth_image wrote (R, G, B or Y float channels) as CV_32FC3 / CV_32FC1.
cv::Mat read_truth_image(const std::filesystem::path& path);

}  // namespace rsibr
