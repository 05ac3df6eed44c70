// An approximate warp against the exact per-texel warp, over one destination map (the tessellated
// and double-indirection warps' tests).
#pragma once

#include "runtime/warp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rsibr::testing {

struct WarpError {
  double max_texels = 0, rms_texels = 0;
  long texels = 0;
};

// Source-position error in source texels over the n x n destination's texels whose exact sample has
// rim >= rim_min; every sample of `approx` must be finite and inside the disc.
inline WarpError compare_to_exact(const Warp& approx, WarpKind kind, const Mat3& m, int n, double rim_min) {
  const ExactWarp exact;
  std::vector<WarpSample> a(static_cast<std::size_t>(n)), e(static_cast<std::size_t>(n));
  WarpError out;
  double sum = 0;
  for (int r = 0; r < n; ++r) {
    const auto [c0, c1] = disc_span(r, n, n);
    if (c0 == c1) continue;
    approx.warp_row(kind, m, n, n, r, c0, c1, a.data());
    exact.warp_row(kind, m, n, n, r, c0, c1, e.data());
    for (int i = 0; i < c1 - c0; ++i) {
      const WarpSample& s = a[std::size_t(i)];
      EXPECT_TRUE(s.disc.allFinite() && std::isfinite(s.rim));
      EXPECT_LE(s.disc.squaredNorm(), 1.0 + 1e-12);
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

}  // namespace rsibr::testing
