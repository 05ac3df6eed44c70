#include "hdr/saturation_level.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

int default_saturation_code(int max_code) { return max_code - max_code / 200; }

SaturationLevel detect_saturation(const std::vector<const BracketSet*>& views) {
  if (views.empty()) throw std::invalid_argument("detect_saturation: no views");
  BracketStatistics stats(int(views.size()));
  for (const BracketSet* b : views) stats.add(*b);
  return detect_saturation(stats);
}

SaturationLevel detect_saturation(const BracketStatistics& st) {
  const int max_code = st.max_code, shift = st.shift, bins = st.bins;
  const int top = default_saturation_code(max_code);
  SaturationLevel out;
  out.source = "detected";
  out.code = {top, top, top};
  if (bins == 0) {
    out.source = "default";
    return out;
  }
  for (int ch = 0; ch < 3; ++ch) {
    // hist[zj][zk]: how often the longer bracket read zk where the shorter read zj (binned).
    const std::vector<long>& hist = st.pair_histogram[std::size_t(ch)];
    // Onset: the lowest z_j whose median z_k is at the top pile-up (and stays there above it).
    const int top_bin = top >> shift;
    int onset = -1;
    for (int zj = bins - 1; zj >= 0; --zj) {
      long n = 0;
      for (int zk = 0; zk < bins; ++zk) n += hist[std::size_t(zj) * std::size_t(bins) + std::size_t(zk)];
      if (n < 20) continue;  // too few pixels at this code to say; keep looking below
      long below = 0;
      int median = 0;
      for (int zk = 0; zk < bins; ++zk) {
        below += hist[std::size_t(zj) * std::size_t(bins) + std::size_t(zk)];
        if (2 * below >= n) {
          median = zk;
          break;
        }
      }
      if (median < top_bin) break;
      onset = zj;
    }
    if (onset < 0) continue;
    // Saturated codes: z_k where z_j is past the onset by max_code / 20.
    const int deep = onset + std::max(1, (max_code / 20) >> shift);
    std::vector<long> sat(std::size_t(bins), 0);
    long total = 0;
    for (int zj = deep; zj < bins; ++zj)
      for (int zk = 0; zk < bins; ++zk) {
        const long h = hist[std::size_t(zj) * std::size_t(bins) + std::size_t(zk)];
        sat[std::size_t(zk)] += h;
        total += h;
      }
    out.evidence[std::size_t(ch)] = total;
    if (total < 200) continue;
    long acc = 0;
    int q = 0;
    for (int zk = 0; zk < bins; ++zk) {
      acc += sat[std::size_t(zk)];
      if (acc > total / 100) {
        q = zk;
        break;
      }
    }
    const int code = std::clamp(q << shift, max_code / 2, top);
    out.code[std::size_t(ch)] = code;
  }
  if (out.evidence[0] < 200 && out.evidence[1] < 200 && out.evidence[2] < 200) out.source = "default";
  return out;
}

}  // namespace rsibr
