#include "runtime/warp.h"

#include "analytic_map_set.h"
#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

using testing::random_directions;

// A random rotation (world_from_view for a random view and a random up).
Mat3 random_frame(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return world_from_view_for(Vec3(g(rng), g(rng), g(rng)), Vec3(g(rng), g(rng), g(rng)));
}

// For `trials` random source_from_dest rotations M (and m, M in float, row-major), both central
// direction kinds and every row of a W x H destination: f(kind, M, m, row, c0, c1) over the row's
// disc span [c0, c1).
template <class F>
void for_each_row_warp(std::mt19937& rng, int trials, int W, int H, const F& f) {
  for (int trial = 0; trial < trials; ++trial) {
    const Mat3 M = random_frame(rng).transpose() * random_frame(rng);
    float m[9];
    for (int i = 0; i < 9; ++i) m[i] = float(M(i / 3, i % 3));
    for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
      for (int r = 0; r < H; ++r) {
        const auto [c0, c1] = disc_span(r, W, H);
        f(kind, M, m, r, c0, c1);
      }
  }
}

TEST(Warp, WarpDirectionAgreesBitwiseWithCoreInverses) {
  for (const Vec3& d : random_directions(2000, 1)) {
    const WarpSample m = warp_direction(CentralDirection::Mirror, d);
    const Vec2 core_m = sphere_map::g_mirror_inv(d);
    EXPECT_EQ(m.disc.x(), core_m.x());
    EXPECT_EQ(m.disc.y(), core_m.y());
    // rim = z of the half vector = sqrt(1 - |disc|^2) = sin(phi/2), phi = angle(d, -z).
    EXPECT_NEAR(m.rim, std::sin(0.5 * angle_between(d, Vec3(0, 0, -1))), 1e-12);
    const WarpSample n = warp_direction(CentralDirection::Normal, d);
    const Vec2 core_n = sphere_map::g_normal_inv(d);
    EXPECT_EQ(n.disc.x(), core_n.x());
    EXPECT_EQ(n.disc.y(), core_n.y());
    EXPECT_NEAR(n.rim, d.z(), 1e-15);
  }
}

TEST(Warp, SingularDirectionsGiveAFixedRimPointWithZeroRim) {
  const WarpSample m = warp_direction(CentralDirection::Mirror, Vec3(0, 0, -1));
  EXPECT_EQ(m.disc, Vec2(0, -1));
  EXPECT_EQ(m.rim, 0.0);
  const WarpSample n = warp_direction(CentralDirection::Normal, Vec3(0, 0, -2));
  EXPECT_EQ(n.disc, Vec2(0, -1));
  EXPECT_EQ(n.rim, -1.0);
  const WarpSample z = warp_direction(CentralDirection::Mirror, Vec3(0, 0, 0));
  EXPECT_TRUE(z.disc.allFinite());
  EXPECT_EQ(z.rim, 0.0);
}

// The invariant itself: the destination texel and the source point it warps to have the same
// central direction in world space (mirror direction for the mirror warp, normal for the normal warp).
TEST(Warp, ExactWarpLandsWhereTheSourceShowsTheSameCentralDirection) {
  std::mt19937 rng(7);
  const ExactWarp warp;
  const int W = 48, H = 48;
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 T_d = random_frame(rng), T_s = random_frame(rng);
    for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal}) {
      for (int r = 0; r < H; ++r) {
        const auto [c0, c1] = disc_span(r, W, H);
        std::vector<WarpSample> out(std::size_t(std::max(0, c1 - c0)));
        warp.warp_row(kind, T_s.transpose() * T_d, W, H, r, c0, c1, out.data());
        for (int c = c0; c < c1; ++c) {
          const WarpSample& s = out[std::size_t(c - c0)];
          ASSERT_LE(s.disc.squaredNorm(), 1.0 + 1e-12);
          if (s.rim < 1e-3) continue;  // near the singularity the disc point is ill-conditioned
          const Vec3 dest = T_d * central_direction(kind, sphere_map::disc_from_pixel(Vec2(c, r), W, H));
          const Vec3 src = T_s * central_direction(kind, s.disc);
          ASSERT_LT((dest - src).norm(), 1e-9) << to_string(kind) << " texel " << c << "," << r;
        }
      }
    }
  }
}

TEST(Warp, IdentityFrameMapsEveryTexelCentreToItself) {
  const ExactWarp warp;
  const int W = 64, H = 64;
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
    for (int r = 0; r < H; ++r) {
      const auto [c0, c1] = disc_span(r, W, H);
      std::vector<WarpSample> out(std::size_t(std::max(0, c1 - c0)));
      warp.warp_row(kind, Mat3::Identity(), W, H, r, c0, c1, out.data());
      for (int c = c0; c < c1; ++c) {
        const Vec2 p = sphere_map::pixel_from_disc(out[std::size_t(c - c0)].disc, W, H);
        ASSERT_NEAR(p.x(), c, 1e-9);
        ASSERT_NEAR(p.y(), r, 1e-9);
      }
    }
}

TEST(Warp, DiscSpanHoldsExactlyTheTexelsWhoseCentreIsInsideTheDisc) {
  for (auto [W, H] : {std::pair{64, 64}, std::pair{33, 33}, std::pair{40, 24}, std::pair{2, 2}, std::pair{1, 1}})
    for (int r = 0; r < H; ++r) {
      const auto [c0, c1] = disc_span(r, W, H);
      for (int c = 0; c < W; ++c) {
        const bool inside = sphere_map::disc_from_pixel(Vec2(c, r), W, H).squaredNorm() <= 1.0;
        EXPECT_EQ(inside, c >= c0 && c < c1) << W << "x" << H << " texel " << c << "," << r;
      }
    }
}

TEST(Warp, PrecomputedWarpMatchesExactWarp) {
  std::mt19937 rng(11);
  const ExactWarp exact;
  for (auto [W, H] : {std::pair{64, 64}, std::pair{37, 29}}) {
    const PrecomputedWarp pre(W, H);
    EXPECT_TRUE(pre.supports(W, H));
    EXPECT_FALSE(pre.supports(W + 1, H));
    double worst = 0;
    for (int trial = 0; trial < 10; ++trial) {
      const Mat3 M = random_frame(rng).transpose() * random_frame(rng);
      for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
        for (int r = 0; r < H; ++r) {
          const auto [c0, c1] = disc_span(r, W, H);
          std::vector<WarpSample> a(std::size_t(std::max(0, c1 - c0))), b(a.size());
          exact.warp_row(kind, M, W, H, r, c0, c1, a.data());
          pre.warp_row(kind, M, W, H, r, c0, c1, b.data());
          for (std::size_t i = 0; i < a.size(); ++i) {
            worst = std::max({worst, (a[i].disc - b[i].disc).norm(), std::abs(a[i].rim - b[i].rim)});
          }
        }
    }
    EXPECT_LE(worst, 1e-12) << W << "x" << H;  // same arithmetic: bitwise in practice
    std::vector<WarpSample> out(4);
    EXPECT_THROW(pre.warp_row(CentralDirection::Mirror, Mat3::Identity(), W + 2, H, 0, 0, 1, out.data()),
                 std::invalid_argument);
  }
}

TEST(Warp, UnknownWarpNameIsAnError) {
  EXPECT_EQ(central_direction_from_string("mirror"), CentralDirection::Mirror);
  EXPECT_EQ(central_direction_from_string("normal"), CentralDirection::Normal);
  EXPECT_THROW(central_direction_from_string("Mirror"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr

namespace rsibr {
namespace {

// The single-precision row warp (the blend engine's form) against warp_direction in double: the
// same map up to float rounding (the disc point relative to its conditioning, ~1/rim near the
// singularity), and ExactWarp's and PrecomputedWarp's warp_block give the same bits.
TEST(Warp, RowWarpAgreesWithWarpDirectionToFloatRounding) {
  std::mt19937 rng(5);
  for (auto [W, H] : {std::pair{64, 64}, std::pair{129, 129}, std::pair{40, 24}}) {
    double worst_disc = 0, worst_rim = 0, worst_dir = 0;
    int differing_blocks = 0;
    const PrecomputedWarp pre(W, H);
    const ExactWarp exact;
    for_each_row_warp(rng, 10, W, H, [&](CentralDirection kind, const Mat3& M, const float* m, int r, int c0, int c1) {
      const int n = c1 - c0;
      const std::size_t count = std::size_t(n);
      std::vector<float> x(count), y(count), z(count), dx(count), dy(count), rim(count);
      central_directions_row(kind, W, H, r, c0, c1, x.data(), y.data(), z.data());
      warp_directions(kind, m, n, x.data(), y.data(), z.data(), dx.data(), dy.data(), rim.data());
      for (int i = 0; i < n; ++i) {
        const Vec3 dir = central_direction(kind, sphere_map::disc_from_pixel(Vec2(c0 + i, r), W, H));
        worst_dir = std::max(worst_dir, (dir - Vec3(x[std::size_t(i)], y[std::size_t(i)], z[std::size_t(i)])).norm());
        const WarpSample s = warp_direction(kind, M * dir);
        worst_rim = std::max(worst_rim, std::abs(s.rim - rim[std::size_t(i)]));
        // Conditioning: d disc / d direction ~ 1 / (2 rim) (mirror), 1 / |n_xy| (normal behind).
        const double cond = std::max(
            kind == CentralDirection::Normal && s.rim < 0 ? (M * dir).head<2>().norm() : std::abs(s.rim), 1e-3);
        worst_disc = std::max(worst_disc, cond * (s.disc - Vec2(dx[std::size_t(i)], dy[std::size_t(i)])).norm());
      }
      std::vector<float> ex(count), ey(count), er(count), px(count), py(count), pr(count);
      exact.warp_block(kind, M, W, H, r, c0, c1, ex.data(), ey.data(), er.data());
      pre.warp_block(kind, M, W, H, r, c0, c1, px.data(), py.data(), pr.data());
      differing_blocks += ex != px || ey != py || er != pr;
    });
    std::printf("[ row warp %dx%d ] direction %.2e, rim %.2e, disc x rim %.2e\n", W, H, worst_dir, worst_rim,
                worst_disc);
    // float: 2^-24 = 6e-8 per rounding; a handful of roundings per result.
    EXPECT_LE(worst_dir, 1e-6);
    EXPECT_LE(worst_rim, 1e-6);
    EXPECT_LE(worst_disc, 1e-6);
    EXPECT_EQ(differing_blocks, 0) << "exact and precomputed warp_block differ";
  }
}

}  // namespace
}  // namespace rsibr

#include "runtime/tessellated_warp.h"

namespace rsibr {
namespace {

// central_block is what lets the blend engine compute a row's central directions once for all of
// its sources: warp_directions on them must give warp_block's bits, for the exact and the
// precomputed warp; a warp that interpolates (tessellated) declines and writes nothing.
TEST(Warp, CentralBlockThenRotationEqualsWarpBlockToTheBit) {
  std::mt19937 rng(17);
  for (auto [W, H] : {std::pair{64, 64}, std::pair{37, 29}}) {
    const ExactWarp exact;
    const PrecomputedWarp pre(W, H);
    int compared = 0;
    for_each_row_warp(rng, 4, W, H, [&](CentralDirection kind, const Mat3& M, const float* m, int r, int c0, int c1) {
      const std::size_t n = std::size_t(std::max(0, c1 - c0));
      for (const Warp* warp : {static_cast<const Warp*>(&exact), static_cast<const Warp*>(&pre)}) {
        std::vector<float> x(n), y(n), z(n), a(n), b(n), c(n), p(n), q(n), s(n);
        ASSERT_TRUE(warp->central_block(kind, W, H, r, c0, c1, x.data(), y.data(), z.data())) << warp->name();
        warp_directions(kind, m, int(n), x.data(), y.data(), z.data(), a.data(), b.data(), c.data());
        warp->warp_block(kind, M, W, H, r, c0, c1, p.data(), q.data(), s.data());
        ASSERT_TRUE(a == p && b == q && c == s) << warp->name() << " row " << r;
        compared += int(n);
      }
    });
    EXPECT_GT(compared, 4 * 2 * 2 * W * H / 2);
  }
  const TessellatedWarp mesh(32, 32);
  float x[4] = {7, 7, 7, 7}, y[4], z[4];
  EXPECT_FALSE(mesh.central_block(CentralDirection::Mirror, 32, 32, 16, 10, 14, x, y, z));
  EXPECT_EQ(x[0], 7.0f);
}

}  // namespace
}  // namespace rsibr
