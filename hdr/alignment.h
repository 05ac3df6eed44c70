// Registration of a view's brackets before the merge: OpenCV's median threshold bitmaps (Ward
// 2003, cv::AlignMTB::calculateShift) on 8-bit grey versions, each bracket against the middle
// one, translation only (handheld brackets and hand-cropped files; rotation is not modelled).
//
// Modes: off; automatic (the default of rsibr hdr and process): a bracket is moved only when the
// shift makes the two threshold bitmaps disagree on at most 0.8 times the pixels they disagree
// on unshifted (outside both exclusion bitmaps, compared on at least 1% of the frame: a bracket
// white or black almost everywhere has no bitmap, and MTB's shift for it is noise), by more than
// 4 sigma of their counts plus 20 pixels, so tripod brackets are never moved; always: every shift MTB finds (the old `--align`).
//
// Pixels a moved bracket no longer covers are marked in BracketSet::covered (not data: the merge
// leaves them out of that bracket only); brackets of different sizes (load_brackets with
// fit_sizes) arrive centred on the middle one's frame with their padding uncovered, and are then
// registered whatever the mode, except off.
#pragma once

#include "hdr/bracket_set.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rsibr {

enum class Alignment { off, automatic, always };
const char* to_string(Alignment a);
// "off", "auto" or "on"; throws std::invalid_argument naming the value otherwise.
Alignment parse_alignment(const std::string& s);

struct AlignmentResult {
  std::vector<cv::Point> shifts;        // applied, per bracket (pixels, x right, y down; the middle one (0, 0))
  std::vector<cv::Point> found;         // what MTB found, per bracket
  std::vector<double> mismatch_before;  // fraction of compared pixels whose bitmaps disagree, unshifted
  std::vector<double> mismatch_after;   // ... at the found shift
};

// Registers `brackets` in place (see above). max_bits: pyramid levels (shifts up to about
// 2^max_bits pixels). Images under 32 px a side are left as they are.
AlignmentResult align_brackets(BracketSet& brackets, Alignment mode = Alignment::always, int max_bits = 6);

}  // namespace rsibr
