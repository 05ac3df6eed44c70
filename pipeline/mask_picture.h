// The picture of one chrome view's mask for the report: the extracted map (tone-mapped) beside the
// same map with its confidence shown, texels of confidence 0 inside the disc in red (the camera,
// the photographer, the stands, the other balls, clipped pixels, the rim) and partial confidence
// darkened. Each texel drawn as `zoom` x `zoom` pixels. BGR, 8-bit, ready for PNG.
#pragma once

#include "formats/map_set.h"

#include <opencv2/core.hpp>

namespace rsibr {

cv::Mat mask_picture(const MapView& chrome, float exposure_stops, int zoom = 4);

}  // namespace rsibr
