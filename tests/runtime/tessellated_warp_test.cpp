// The paper's tessellated-disk warp against the exact per-texel warp.
#include "runtime/tessellated_warp.h"

#include "analytic_map_set.h"
#include "warp_error.h"
#include "runtime/blend.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

std::vector<Mat3> rotations(int count) {
  std::vector<Mat3> out;
  for (const Vec3& v : testing::random_directions(count, 17)) {
    const Mat3 Td = world_from_view_for(v);
    const Mat3 Ts =
        world_from_view_for((v + 0.6 * testing::random_directions(1, unsigned(out.size()) + 3)[0]).normalized());
    out.push_back(Ts.transpose() * Td);  // a source about 35 degrees from the destination
  }
  return out;
}

TEST(TessellatedWarp, ApproachesTheExactWarpAsTheMeshRefines) {
  const int n = 256;
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal}) {
    double previous = INFINITY;
    for (int rings : {8, 16, 32}) {
      const TessellatedWarp warp(n, n, {rings, 4 * rings});
      double rms = 0, worst = 0;
      for (const Mat3& m : rotations(6)) {
        const testing::WarpError e = testing::compare_to_exact(warp, kind, m, n, 0.3);
        EXPECT_EQ(e.bad, 0);
        rms = std::max(rms, e.rms_texels);
        worst = std::max(worst, e.max_texels);
      }
      std::printf("  %-6s rings %2d segments %3d: source-position error rms %.3f, max %.3f texels (256^2)\n",
                  to_string(kind), rings, 4 * rings, rms, worst);
      // Second order away from the singularity (4x per doubling for the normal warp); the mirror warp
      // bends faster near -v_s and gains 1.9x, then 3.4x.
      EXPECT_LT(rms, 0.6 * previous) << to_string(kind) << " " << rings;
      previous = rms;
    }
    EXPECT_LT(previous, 0.1) << to_string(kind);  // 32 x 128 mesh: a tenth of a texel
  }
}

TEST(TessellatedWarp, CellsStraddlingTheSingularityAreWarpedExactly) {
  // Source and destination facing each other: the mirror singularity -v_s is inside the destination.
  const int n = 128;
  const Mat3 Td = world_from_view_for(Vec3(0, 0, 1)), Ts = world_from_view_for(Vec3(0.2, 0.1, -1).normalized());
  const Mat3 m = Ts.transpose() * Td;
  const TessellatedWarp warp(n, n);
  EXPECT_GT(warp.exact_cells(CentralDirection::Mirror, m), 0);
  const ExactWarp exact;
  std::vector<WarpSample> a(static_cast<std::size_t>(n)), e(static_cast<std::size_t>(n));
  int singular = 0;
  for (int r = 0; r < n; ++r) {
    const auto [c0, c1] = disc_span(r, n, n);
    if (c0 == c1) continue;
    warp.warp_row(CentralDirection::Mirror, m, n, n, r, c0, c1, a.data());
    exact.warp_row(CentralDirection::Mirror, m, n, n, r, c0, c1, e.data());
    for (int i = 0; i < c1 - c0; ++i) {
      ASSERT_TRUE(a[std::size_t(i)].disc.allFinite());
      ASSERT_LE(a[std::size_t(i)].disc.norm(), 1.0 + 1e-12);
      if (e[std::size_t(i)].rim < 0.02) {  // within ~2.3 degrees of -v_s: must be the exact warp
        ++singular;
        EXPECT_EQ(a[std::size_t(i)].disc, e[std::size_t(i)].disc);
      }
    }
  }
  EXPECT_GT(singular, 0);
}

TEST(TessellatedWarp, BlendMatchesTheExactBlend) {
  const int n = 128;
  const ViewSet views = ViewSet::icosahedron();
  const MapSet set = testing::analytic_map_set(views, n, n, "mirror", testing::mirror_texel);
  const TessellatedWarp tess(n, n, {32, 128});
  for (const Vec3& v : testing::random_directions(5, 9)) {
    BlendOptions exact_options, tess_options;
    tess_options.warp = &tess;
    const BlendResult a = blend(set, views, v, Vec3(0, 1, 0), exact_options);
    const BlendResult b = blend(set, views, v, Vec3(0, 1, 0), tess_options);
    double worst = 0, sum = 0;
    long count = 0;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const cv::Vec3f p = a.rgb.at<cv::Vec3f>(r, c), q = b.rgb.at<cv::Vec3f>(r, c);
        for (int k = 0; k < 3; ++k) {
          ASSERT_TRUE(std::isfinite(q[k]));
          worst = std::max(worst, double(std::abs(p[k] - q[k])));
          sum += double(p[k] - q[k]) * double(p[k] - q[k]);
          ++count;
        }
      }
    EXPECT_LT(std::sqrt(sum / count), 2e-3) << v.transpose();
    EXPECT_LT(worst, 0.1) << v.transpose();
  }
}

TEST(TessellatedWarp, RejectsOtherSizesAndBadMeshes) {
  const TessellatedWarp warp(32, 32);
  EXPECT_FALSE(warp.supports(64, 64));
  std::vector<WarpSample> out(8);
  EXPECT_THROW(warp.warp_row(CentralDirection::Mirror, Mat3::Identity(), 64, 64, 0, 0, 8, out.data()),
               std::invalid_argument);
  EXPECT_THROW(TessellatedWarp(32, 32, {0, 8}), std::invalid_argument);
  EXPECT_THROW(TessellatedWarp(32, 32, {4, 2}), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
