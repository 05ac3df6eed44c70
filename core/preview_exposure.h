// The exposure of a PNG preview, metered on the scene's middle tone. The median luminance (Rec.709 weights, working space) of the pixels
// that hold light maps to display mid-grey 0.18, so a lamp, a window or the sun (a few pixels
// thousands of times brighter) does not darken the picture the way a mean-based exposure does,
// and a scene in large units (an HDR merge's X/e) is not shown white.
//
// Pixels that hold light: finite luminance > 0, alpha > 0 for RGBA images (a sphere map's disc),
// and mask != 0 when a mask is given (e.g. not clipped). At most about 2^20 pixels are read, on a
// regular grid, so the result is deterministic.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

// Stops to multiply by (2^stops) before display; 0 when no pixel holds light. rgb: CV_32FC3 or
// CV_32FC4, RGB(A). mask: empty or CV_8UC1 of the same size.
float preview_exposure(const cv::Mat& rgb, const cv::Mat& mask = cv::Mat());
// Several pictures shown at one exposure (the panels of a comparison, a turntable): metered
// together. masks: empty, or one per image (each may be empty).
float preview_exposure(const std::vector<cv::Mat>& rgb, const std::vector<cv::Mat>& masks = {});

}  // namespace rsibr
