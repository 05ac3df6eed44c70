// The code at which each channel saturates, measured from the brackets themselves, and the rule
// that says when a bracket is saturated at a pixel.
//
// A lossless camera file saturates at its top code (a pile-up in the histogram); a JPEG does not:
// compression rings around clipped highlights and the 4:2:0 chroma smears them, so saturated
// signal arrives a few to tens of codes below the top. Measured where the brackets stop agreeing:
// for bracket pairs j < k with e_k / e_j >= 1.5, the median code of the longer one given the
// shorter one's code, m(z_j) = median{z_k | z_j}, rises with z_j until it reaches the pile-up at
// the top; past that onset z* (plus a margin of max_code / 20 in z_j, so that r X(z_j) is well past
// saturation) every z_k is a saturated code. The channel's saturation code is the 1% quantile of
// those codes (at most max_code - max_code / 200, the lossless default; at least max_code / 2).
//
// Consistency (saturated_from): a bracket is saturated at a pixel when any channel's code is at or
// above that channel's saturation code, and then so is every longer bracket (more exposure cannot
// unsaturate a pixel: a longer bracket that reads lower is a JPEG artefact or motion, not data).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/bracket_statistics.h"

#include <array>
#include <string>
#include <vector>

namespace rsibr {

struct SaturationLevel {
  std::array<int, 3> code{0, 0, 0};       // per channel: codes at or above are saturated
  std::array<long, 3> evidence{0, 0, 0};  // saturated codes measured per channel (0: default used)
  std::string source;                     // "detected", "default" (too little evidence) or "given"
};

int default_saturation_code(int max_code);

// Measures every channel's saturation code from the pair histograms of every view. A channel with
// fewer than 200 measured saturated codes keeps the default.
SaturationLevel detect_saturation(const BracketStatistics& stats);
SaturationLevel detect_saturation(const std::vector<const BracketSet*>& views);

// The same rule on codes laid out [bracket][channel] (BracketStatistics' grids).
inline int saturated_from(const std::uint16_t* codes, int brackets, const std::array<int, 3>& sat) {
  for (int j = 0; j < brackets; ++j) {
    const std::uint16_t* z = codes + 3 * j;
    if (z[0] >= sat[0] || z[1] >= sat[1] || z[2] >= sat[2]) return j;
  }
  return brackets;
}

// Index of the shortest bracket saturated at the pixel under the consistency rule (size() when
// none): codes[j] is pixel (r, c) of every bracket.
inline int saturated_from(const BracketSet& b, int r, int c, const std::array<int, 3>& sat) {
  for (int j = 0; j < int(b.size()); ++j) {
    const auto* z = b.codes[std::size_t(j)].ptr<std::uint16_t>(r) + 3 * c;
    if (z[0] >= sat[0] || z[1] >= sat[1] || z[2] >= sat[2]) return j;
  }
  return int(b.size());
}

}  // namespace rsibr
