// An approximate warp against the exact per-texel warp over n x n destination maps (the tessellated
// and double-indirection warps' tests, bench/warp_methods.cpp).
#pragma once

#include "runtime/warp.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace rsibr::testing {

struct WarpError {
  double max_texels = 0, rms_texels = 0;  // source-position error, source texels
  long texels = 0;                        // texels compared (exact rim >= rim_min)
  long bad = 0;                           // samples non-finite or outside the disc (any rim)
};

// Pooled over the sources (source_from_dest rotations): the error over destination texels whose exact
// sample has rim >= rim_min, and every sample of `approx` checked for finiteness and the disc.
inline WarpError compare_to_exact(const Warp& approx, CentralDirection kind, const std::vector<Mat3>& sources, int n,
                                  double rim_min) {
  const ExactWarp exact;
  std::vector<WarpSample> a(static_cast<std::size_t>(n)), e(static_cast<std::size_t>(n));
  WarpError out;
  double sum = 0;
  for (const Mat3& m : sources)
    for (int r = 0; r < n; ++r) {
      const auto [c0, c1] = disc_span(r, n, n);
      if (c0 == c1) continue;
      approx.warp_row(kind, m, n, n, r, c0, c1, a.data());
      exact.warp_row(kind, m, n, n, r, c0, c1, e.data());
      for (int i = 0; i < c1 - c0; ++i) {
        const WarpSample& s = a[std::size_t(i)];
        if (!(s.disc.allFinite() && std::isfinite(s.rim) && s.disc.squaredNorm() <= 1.0 + 1e-12)) ++out.bad;
        if (e[std::size_t(i)].rim < rim_min) continue;
        const double d = (s.disc - e[std::size_t(i)].disc).norm() * n / 2;
        out.max_texels = std::max(out.max_texels, d);
        sum += d * d;
        ++out.texels;
      }
    }
  out.rms_texels = out.texels ? std::sqrt(sum / out.texels) : 0;
  return out;
}

inline WarpError compare_to_exact(const Warp& approx, CentralDirection kind, const Mat3& m, int n, double rim_min) {
  return compare_to_exact(approx, kind, std::vector<Mat3>{m}, n, rim_min);
}

}  // namespace rsibr::testing
