// A view's linear image as calibration reads it: a merged view of `rsibr hdr` (R, G, B, variance,
// clipped/black/ghost flags; hdr/merged_exr.h) or any float RGB OpenEXR (e.g. the truth radiance
// of `rsibr synth`), with the camera's orientation when the header carries one
// (rsibr.worldFromCam, M33f, columns = camera x right, y down, z forward in world) and the view's
// name when the header carries one (rsibr.view, a string).
#pragma once

#include "core/vec.h"

#include <opencv2/core.hpp>

#include <optional>
#include <string>

namespace rsibr {

struct ViewImage {
  cv::Mat radiance;  // CV_32FC3 RGB
  cv::Mat flags;     // CV_8UC1 hdr/merge.h MergeFlag bits, or empty (not a merged view)
  std::optional<Mat3> world_from_cam;
  bool merged = false;
  std::string name;  // the header's rsibr.view string attribute (rsibr hdr writes the view's name), or empty
};

// Throws FileError(path, problem) (formats/file_error.h).
ViewImage read_view_image(const std::string& path);

}  // namespace rsibr
