// Sphere-map coordinates (docs/conventions.md), including the paper's misprinted g_mirror^-1 (squared divisor).
#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

using namespace sphere_map;

Vec2 random_disc_point(std::mt19937& rng, double max_radius = 1.0) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    Vec2 p(u(rng), u(rng));
    if (p.norm() <= max_radius) return p;
  }
}

TEST(SphereMap, TexelCentreConventionHasTUp) {
  // Texel (0,0) is the top-left: s = 0.5/W, t = 1 - 0.5/H, i.e. disc x < 0, y > 0.
  const int W = 8, H = 4;
  const Vec2 xy = disc_from_pixel(Vec2(0, 0), W, H);
  EXPECT_DOUBLE_EQ(st_from_disc(xy).x(), 0.5 / W);
  EXPECT_DOUBLE_EQ(st_from_disc(xy).y(), 1.0 - 0.5 / H);
  const Vec2 back = pixel_from_disc(xy, W, H);
  EXPECT_NEAR(back.x(), 0.0, 1e-12);
  EXPECT_NEAR(back.y(), 0.0, 1e-12);
}

TEST(SphereMap, CentreNormalFacesTheViewerAndMirrorsBackToIt) {
  EXPECT_EQ(g_normal(Vec2(0, 0)), Vec3(0, 0, 1));
  EXPECT_EQ(g_mirror(Vec2(0, 0)), Vec3(0, 0, 1));
}

TEST(SphereMap, RimMirrorsToTheDirectionBehindTheSphere) {
  // A rim point given to double precision has z = sqrt(rounding) ~ 1e-8: the map's derivative is
  // unbounded at the rim, so that is the accuracy any representation in (x, y) can have there.
  for (double a = 0; a < 2 * kPi; a += 0.1) {
    const Vec3 r = g_mirror(Vec2(std::cos(a), std::sin(a)));
    EXPECT_NEAR((r - Vec3(0, 0, -1)).norm(), 0.0, 1e-7);
  }
  // The singular direction itself maps to a rim point, deterministically.
  const Vec2 xy = g_mirror_inv(Vec3(0, 0, -1));
  EXPECT_NEAR(xy.norm(), 1.0, 1e-15);
  EXPECT_EQ(xy, g_mirror_inv(Vec3(0, 0, -1)));
}

TEST(SphereMap, MirrorInverseUsesTheHalfVectorNotItsSquare) {
  std::mt19937 rng(7);
  double worst = 0, worst_printed = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec2 xy = random_disc_point(rng, 0.999);
    const Vec3 r = g_mirror(xy);
    worst = std::max(worst, (g_mirror_inv(r) - xy).norm());
    // The paper's printed formula divides by |r+z|^2 instead of |r+z|.
    const Vec3 h = r + Vec3(0, 0, 1);
    worst_printed = std::max(worst_printed, (Vec2(h.x(), h.y()) / h.squaredNorm() - xy).norm());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(worst_printed, 0.1);
}

TEST(SphereMap, MirrorInverseIsAccurateNextToTheSingularity) {
  // Directions within 1e-7 rad of -z: 1 + r.z cancels; the guarded form keeps the error at the
  // level the disc coordinates can represent (~1e-16 / eps), far below the 1e-5 rad budget. The
  // unguarded 1 + r.z loses everything for eps < 1e-8.
  for (double eps : {1e-3, 1e-5, 1e-7}) {
    for (double a = 0; a < 2 * kPi; a += 0.7) {
      const Vec3 r(std::sin(eps) * std::cos(a), std::sin(eps) * std::sin(a), -std::cos(eps));
      const Vec3 back = g_mirror(g_mirror_inv(r));
      EXPECT_LT(angle_between(back, r), 1e-15 / eps + 1e-12) << "eps " << eps;
    }
  }
}

TEST(SphereMap, NormalInverseRoundTrips) {
  std::mt19937 rng(3);
  for (int i = 0; i < 10000; ++i) {
    const Vec2 xy = random_disc_point(rng);
    EXPECT_LT((g_normal_inv(g_normal(xy)) - xy).norm(), 1e-12);
  }
  // Normals facing away clamp to the rim; zero vectors give the centre, never NaN.
  EXPECT_NEAR(g_normal_inv(Vec3(0.3, 0.4, -0.5)).norm(), 1.0, 1e-15);
  EXPECT_EQ(g_normal_inv(Vec3::Zero()), Vec2(0, 0));
  EXPECT_EQ(g_mirror_inv(Vec3::Zero()), Vec2(0, 0));
}

TEST(SphereMap, DiscRectAreaIsExact) {
  EXPECT_NEAR(disc_rect_area(-1, 1, -1, 1), kPi, 1e-14);
  EXPECT_NEAR(disc_rect_area(0, 1, 0, 1), kPi / 4, 1e-14);
  EXPECT_NEAR(disc_rect_area(-2, 2, 0, 5), kPi / 2, 1e-14);
  EXPECT_NEAR(disc_rect_area(-0.1, 0.1, -0.1, 0.1), 0.04, 1e-15);  // inside
  EXPECT_EQ(disc_rect_area(0.9, 1.0, 0.9, 1.0), 0.0);              // outside, corner region
  // Random rectangles against a fine midpoint grid.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int i = 0; i < 40; ++i) {
    double x0 = u(rng), x1 = u(rng), y0 = u(rng), y1 = u(rng);
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    const int n = 1500;
    double count = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double x = x0 + (a + 0.5) * (x1 - x0) / n, y = y0 + (b + 0.5) * (y1 - y0) / n;
        count += x * x + y * y <= 1.0;
      }
    const double grid = count * (x1 - x0) * (y1 - y0) / (double(n) * n);
    EXPECT_NEAR(disc_rect_area(x0, x1, y0, y1), grid, 2e-3 * (x1 - x0 + y1 - y0) / 1.0 + 1e-6);
  }
}

}  // namespace
}  // namespace rsibr
