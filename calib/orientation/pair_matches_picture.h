// The picture of what tied two views together (or failed to): the two views side by side
// (tone-mapped at their middle tones, display encoded), each shared track's features joined by a
// line, green where the track is an inlier of the solve, red where not. BGR, 8-bit, for PNG.
#pragma once

#include "calib/orientation/view_orientation.h"

#include <opencv2/core.hpp>

#include <filesystem>

namespace rsibr {

// `a`, `b` CV_32FC3 linear RGB (the pair's views, in the order of PairOrientation's a and b);
// the picture is `height` pixels high (each view scaled to it).
cv::Mat pair_matches_picture(const cv::Mat& a, const cv::Mat& b, const PairOrientation& pair, int height = 600);

// Written atomically as a PNG. Throws std::runtime_error("<png>: ...") when it cannot be written.
void write_pair_matches_picture(const std::filesystem::path& png, const cv::Mat& a, const cv::Mat& b,
                                const PairOrientation& pair);

}  // namespace rsibr
