// Registration of a view's brackets before the merge, each bracket onto the middle one: median
// threshold bitmaps (Ward 2003; OpenCV's cv::AlignMTB::computeBitmaps) on 8-bit grey versions,
// searched coarse to fine. At the coarsest level (the frame halved until its shorter side is at most
// 128 pixels) every shift up to a quarter of the shorter side is tried, the nearer of two equal ones
// winning, then rotations about the centre up to 3 degrees (kept only when they lower the
// disagreement by 5%); each finer level doubles the motion and takes the best of its neighbours
// (one pixel, one angle step that turns the corners by a pixel). A best shift on the edge of the
// window is not applied (the true one may lie beyond it) and is reported (`beyond_search`).
//
// Modes: off; automatic (the default of rsibr hdr and process): a bracket is moved only when the
// motion makes the two threshold bitmaps disagree on at most 0.8 times the pixels they disagree
// on unmoved (outside both exclusion bitmaps, compared on at least 1% of the frame: a bracket
// white or black almost everywhere has no bitmap, and the search's motion for it is noise), by
// more than 4 sigma of their counts plus 20 pixels, so tripod brackets are never moved; always:
// every motion the search finds (the old `--align`).
//
// Pixels a moved bracket no longer covers are marked in BracketSet::covered (not data: the merge
// leaves them out of that bracket only); brackets of different sizes (load_brackets with
// fit_sizes) arrive centred on the middle one's frame with their padding uncovered, and are then
// registered whatever the mode, except off. What is left misregistered (a bracket from another
// place, things that moved) the merge flags as ghost (hdr/merge.h).
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
  std::vector<double> rotation_deg;     // applied, per bracket: about the image centre, before the shift
  std::vector<bool> beyond_search;      // per bracket: the search's best shift was on its window's edge
  std::vector<cv::Point> found;         // what the search found, per bracket
  std::vector<double> mismatch_before;  // fraction of compared pixels whose bitmaps disagree, unshifted
  std::vector<double> mismatch_after;   // ... at the found shift
};

// Registers `brackets` in place (see above). max_bits: the bitmaps' exclusion threshold's pyramid
// depth in OpenCV (unused by the search itself). Images under 32 px a side are left as they are.
AlignmentResult align_brackets(BracketSet& brackets, Alignment mode = Alignment::always, int max_bits = 6);

}  // namespace rsibr
