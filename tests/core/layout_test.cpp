// Environment-map layouts: exact direction <-> pixel mappings and texel solid angles.
#include "core/layout.h"

#include "core/sphere_map.h"

#include <OpenEXR/ImfEnvmap.h>
#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

std::vector<Layout> all_layouts() {
  return {Layout(LayoutKind::LatLong, 512, 256), Layout::with_size(LayoutKind::Cube, 128),
          Layout::with_size(LayoutKind::Octahedral, 256), Layout::with_size(LayoutKind::Sphere, 256),
          Layout(LayoutKind::Sphere, 37, 29)};
}

Vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3 d(n(rng), n(rng), n(rng));
    if (d.norm() > 1e-6) return d.normalized();
  }
}

// Directions where layouts have poles, seams, edges, corners, folds, centre and rim.
std::vector<Vec3> special_directions() {
  std::vector<Vec3> d;
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c)
        if (a || b || c) d.push_back(Vec3(a, b, c).normalized());  // axes, cube edges and corners
  for (double e : {1e-9, 1e-7, 1e-5, 1e-3}) {
    d.push_back(Vec3(e, 1, 0).normalized());  // next to the poles
    d.push_back(Vec3(0, -1, e).normalized());
    d.push_back(Vec3(-e, 0, -1).normalized());  // either side of the lat-long seam
    d.push_back(Vec3(e, 0, -1).normalized());
    d.push_back(Vec3(e, -e, -1).normalized());    // next to the sphere map's singular direction
    d.push_back(Vec3(1, 1 + e, 0).normalized());  // near a cube edge
    d.push_back(Vec3(1, 1, 1 - e).normalized());  // near a cube corner
  }
  d.push_back(Vec3(0, 0, 1));   // sphere-map centre
  d.push_back(Vec3(0, 0, -1));  // sphere-map rim (singular)
  return d;
}

TEST(Layout, DirectionPixelDirectionRoundTripIsExactForEveryLayout) {
  std::mt19937 rng(1);
  std::vector<Vec3> dirs = special_directions();
  for (int i = 0; i < 100000; ++i) dirs.push_back(random_direction(rng));
  for (const Layout& L : all_layouts()) {
    double worst = 0;
    for (const Vec3& d : dirs) {
      const auto back = L.direction(L.pixel(d));
      ASSERT_TRUE(back.has_value()) << to_string(L.kind()) << " lost direction " << d.transpose();
      ASSERT_TRUE(back->allFinite());
      worst = std::max(worst, angle_between(*back, d));
    }
    RecordProperty(to_string(L.kind()) + "_max_error_rad", std::to_string(worst));
    std::printf("  %-10s %4dx%-4d  max round-trip error %.3g rad over %zu directions\n", to_string(L.kind()).c_str(),
                L.width(), L.height(), worst, dirs.size());
    EXPECT_LT(worst, 1e-5) << to_string(L.kind());
  }
}

TEST(Layout, PixelPositionsOfTexelCentresRoundTrip) {
  // Away from places where one direction has several pixels (seams, poles, shared cube edges,
  // octahedral border, sphere rim), pixel -> direction -> pixel is the identity.
  for (const Layout& L : all_layouts()) {
    double worst = 0;
    for (int r = 1; r + 1 < L.height(); ++r)
      for (int c = 1; c + 1 < L.width(); ++c) {
        if (L.kind() == LayoutKind::Cube && (r % L.width() == 0 || r % L.width() == L.width() - 1)) continue;
        const auto d = L.direction(Vec2(c, r));
        if (!d) continue;
        if (L.kind() == LayoutKind::Sphere &&
            sphere_map::disc_from_pixel(Vec2(c, r), L.width(), L.height()).norm() > 0.99)
          continue;
        worst = std::max(worst, (L.pixel(*d) - Vec2(c, r)).norm());
      }
    EXPECT_LT(worst, 2e-3) << to_string(L.kind());  // float OpenEXR maths: ~1e-4 px at 512
  }
}

TEST(Layout, LatLongFollowsOpenExrConvention) {
  const Layout L(LayoutKind::LatLong, 9, 5);
  // Pixel (min.x, min.y) is latitude +pi/2 (+Y); the middle row's first pixel is longitude +pi (-Z),
  // the centre is longitude 0 (+Z), a quarter in is longitude +pi/2 (+X).
  EXPECT_LT(angle_between(*L.direction(Vec2(0, 0)), Vec3(0, 1, 0)), 1e-6);
  EXPECT_LT(angle_between(*L.direction(Vec2(0, 2)), Vec3(0, 0, -1)), 1e-6);
  EXPECT_LT(angle_between(*L.direction(Vec2(4, 2)), Vec3(0, 0, 1)), 1e-6);
  EXPECT_LT(angle_between(*L.direction(Vec2(2, 2)), Vec3(1, 0, 0)), 1e-6);
  EXPECT_LT(angle_between(*L.direction(Vec2(4, 4)), Vec3(0, -1, 0)), 1e-6);
}

TEST(Layout, CubeInverseMatchesOpenExrPixelPosition) {
  const int sof = 16;
  const Layout L = Layout::with_size(LayoutKind::Cube, sof);
  const Imath::Box2i dw(Imath::V2i(0, 0), Imath::V2i(sof - 1, 6 * sof - 1));
  for (int f = 0; f < 6; ++f)
    for (double y = 0; y <= sof - 1; y += 0.5)
      for (double x = 0; x <= sof - 1; x += 0.5) {
        const Imf::CubeMapFace face = Imf::CubeMapFace(f);
        const Imath::V2f pif{float(x), float(y)};
        const Imath::V3f expect = Imf::CubeMap::direction(face, dw, pif);
        const Imath::V2f pos = Imf::CubeMap::pixelPosition(face, dw, pif);
        const Vec3 got = *L.direction(Vec2(pos.x, pos.y));
        EXPECT_LT(angle_between(got, Vec3(expect.x, expect.y, expect.z)), 1e-6) << "face " << f;
      }
}

TEST(Layout, TexelSolidAnglesPartitionTheSphere) {
  std::vector<Layout> layouts = all_layouts();
  layouts.push_back(Layout(LayoutKind::LatLong, 2, 2));
  layouts.push_back(Layout(LayoutKind::LatLong, 7, 3));
  layouts.push_back(Layout::with_size(LayoutKind::Cube, 2));
  layouts.push_back(Layout::with_size(LayoutKind::Octahedral, 2));
  layouts.push_back(Layout::with_size(LayoutKind::Sphere, 2));
  layouts.push_back(Layout::with_size(LayoutKind::Sphere, 3));
  for (const Layout& L : layouts) {
    double sum = 0;
    for (int r = 0; r < L.height(); ++r)
      for (int c = 0; c < L.width(); ++c) {
        const double w = L.texel_solid_angle(c, r);
        ASSERT_GE(w, 0.0);
        sum += w;
      }
    EXPECT_NEAR(sum, 4 * kPi, 1e-10) << to_string(L.kind()) << " " << L.width() << "x" << L.height();
  }
}

TEST(Layout, TexelSolidAngleEqualsTheIntegralOfTheDensity) {
  std::mt19937 rng(5);
  for (const Layout& L : all_layouts()) {
    std::uniform_int_distribution<int> col(0, L.width() - 1), row(0, L.height() - 1);
    for (int i = 0; i < 60; ++i) {
      const int c = col(rng), r = row(rng);
      const int n = 64;
      double sum = 0;
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          sum += L.solid_angle_density(Vec2(c - 0.5 + (k + 0.5) / n, r - 0.5 + (j + 0.5) / n));
      sum /= double(n) * n;
      // Seam columns and pole rows of the lat-long own half a texel; the density does not know.
      if (L.kind() == LayoutKind::LatLong && (c == 0 || c == L.width() - 1 || r == 0 || r == L.height() - 1)) continue;
      if (L.kind() == LayoutKind::Cube &&
          (c == 0 || c == L.width() - 1 || r % L.width() == 0 || r % L.width() == L.width() - 1))
        continue;
      EXPECT_NEAR(L.texel_solid_angle(c, r), sum, 2e-3 * sum + 1e-12) << to_string(L.kind()) << " " << c << "," << r;
    }
  }
}

TEST(Layout, SphereMapIsEqualArea) {
  const Layout L = Layout::with_size(LayoutKind::Sphere, 64);
  EXPECT_NEAR(L.texel_solid_angle(32, 32), 16.0 / (64.0 * 64.0), 1e-15);
  EXPECT_NEAR(L.texel_solid_angle(10, 40), 16.0 / (64.0 * 64.0), 1e-15);
  EXPECT_EQ(L.texel_solid_angle(0, 0), 0.0);  // corner texel: outside the disc
  EXPECT_FALSE(L.direction(Vec2(0, 0)).has_value());
}

TEST(Layout, OctahedralBorderFoldsOntoItself) {
  // (u, 1) and (-u, 1) are the same direction, and likewise on every edge; corners are all -Y.
  for (double u = -1; u <= 1; u += 0.125) {
    EXPECT_LT(angle_between(octahedral_direction(Vec2(u, 1)), octahedral_direction(Vec2(-u, 1))), 1e-15);
    EXPECT_LT(angle_between(octahedral_direction(Vec2(u, -1)), octahedral_direction(Vec2(-u, -1))), 1e-15);
    EXPECT_LT(angle_between(octahedral_direction(Vec2(1, u)), octahedral_direction(Vec2(1, -u))), 1e-15);
    EXPECT_LT(angle_between(octahedral_direction(Vec2(-1, u)), octahedral_direction(Vec2(-1, -u))), 1e-15);
  }
  EXPECT_LT(angle_between(octahedral_direction(Vec2(1, 1)), Vec3(0, -1, 0)), 1e-15);
  EXPECT_LT(angle_between(octahedral_direction(Vec2(0, 0)), Vec3(0, 1, 0)), 1e-15);
  // Image right is +X and image up is -Z (seen from above).
  EXPECT_LT(angle_between(octahedral_direction(Vec2(1, 0)), Vec3(1, 0, 0)), 1e-15);
  EXPECT_LT(angle_between(octahedral_direction(Vec2(0, 1)), Vec3(0, 0, -1)), 1e-15);
}

TEST(Layout, BadSizesAreRejected) {
  EXPECT_THROW(Layout(LayoutKind::Cube, 16, 90), std::invalid_argument);
  EXPECT_THROW(Layout(LayoutKind::Octahedral, 15, 15), std::invalid_argument);
  EXPECT_THROW(Layout(LayoutKind::Octahedral, 16, 18), std::invalid_argument);
  EXPECT_THROW(Layout(LayoutKind::LatLong, 1, 1), std::invalid_argument);
  EXPECT_THROW(parse_layout_kind("mercator"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr

namespace rsibr {
namespace {

TEST(Layout, PixelIsAreaTexelsNestExactly) {
  // The solid angle of a texel equals the sum over the four texels of the double-size map it holds.
  for (LayoutKind kind : {LayoutKind::Sphere, LayoutKind::Octahedral}) {
    for (int n : {4, 8, 16, 32, 64}) {
      const Layout coarse = Layout::with_size(kind, n), fine = Layout::with_size(kind, 2 * n);
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
          double sum = 0;
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) sum += fine.texel_solid_angle(2 * c + i, 2 * r + j);
          ASSERT_NEAR(coarse.texel_solid_angle(c, r), sum, 1e-14)
              << to_string(kind) << " " << n << " " << c << "," << r;
        }
    }
  }
}

}  // namespace
}  // namespace rsibr
