// Optional small-shift alignment of brackets: OpenCV's median threshold bitmap (Ward 2003,
// cv::AlignMTB::calculateShift) on 8-bit grey versions, each bracket against the middle one.
// Translation only; pixels shifted in from outside repeat the edge (they are not new data).
#pragma once

#include "hdr/bracket_set.h"

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

// Shifts every bracket onto the middle one in place; returns the shift applied to each bracket
// (pixels, x right, y down; the middle one's is (0,0)). max_bits: pyramid levels (shifts up to
// about 2^max_bits pixels).
std::vector<cv::Point> align_brackets(BracketSet& brackets, int max_bits = 6);

}  // namespace rsibr
