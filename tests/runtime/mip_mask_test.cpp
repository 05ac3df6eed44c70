// Lookups at a footprint (MIP levels of the sources) and the MIP-mask blend of sets whose maps were
// measured at different resolutions (runtime/blend_engine.h, core/resolution_mask.h).
#include "runtime/blend_engine.h"

#include "core/resolution_mask.h"
#include "runtime/analytic_map_set.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

using testing::analytic_map_set;
using testing::random_directions;

BlendEngine::Footprint footprint_of(const Vec3& n, double size) {
  const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
  BlendEngine::Footprint fp;
  fp.dn_dx = size * a;
  fp.dn_dy = size * b;
  return fp;
}

TEST(LookupAtAFootprint, AZeroFootprintIsTheKernelsTapExactly) {
  const ViewSet views = ViewSet::named("42");
  const MapSet set = analytic_map_set(views, 32, 32, "mirror", testing::mirror_texel);
  const BlendEngine engine(set, views);
  for (const Vec3& v : random_directions(20, 3))
    for (const Vec3& n0 : random_directions(10, 4)) {
      const Vec3 n = n0.dot(v) < 0 ? Vec3(-n0) : n0;
      const ViewWeights located = engine.locate(v);
      double w0 = 0, w1 = 0;
      const Vec3 a = engine.radiance(located, v, n, &w0);
      const Vec3 b = engine.radiance(located, v, n, BlendEngine::Footprint{}, &w1);
      EXPECT_EQ(a, b);
      EXPECT_EQ(w0, w1);
    }
  EXPECT_FALSE(engine.mixed_resolution());
}

TEST(LookupAtAFootprint, ConstantMapsStayConstantAtEveryLevelUpToTheRim) {
  // Coarse levels renormalise by the valid share: a texel half outside the disc is not darker.
  const ViewSet views = ViewSet::named("icosa");
  const MapSet set =
      analytic_map_set(views, 32, 32, "normal", [](const Mat3&, const Vec2&) { return Vec3(0.3, 0.6, 0.9); });
  const BlendEngine engine(set, views);
  for (const Vec3& v : random_directions(10, 5))
    for (const Vec3& n0 : random_directions(20, 6)) {
      const Vec3 n = n0.dot(v) < 0 ? Vec3(-n0) : n0;
      for (double size : {0.01, 0.1, 0.5, 2.0}) {
        const Vec3 L = engine.radiance(engine.locate(v), v, n, footprint_of(n, size));
        EXPECT_NEAR(L.x(), 0.3, 2e-5);
        EXPECT_NEAR(L.y(), 0.6, 2e-5);
        EXPECT_NEAR(L.z(), 0.9, 4e-5);
      }
    }
}

TEST(LookupAtAFootprint, AFootprintOfManyTexelsAveragesATexelChecker) {
  // Every texel alternates 0 / 1: one tap reads 0 or 1 (aliasing), a footprint of 8 texels its mean.
  const ViewSet views = ViewSet::named("icosa");
  MapSet set;
  for (const Vec3& v : views.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v);
    mv.warp = CentralDirection::Normal;
    mv.rgb = cv::Mat::zeros(64, 64, CV_32FC3);
    for (int r = 0; r < 64; ++r)
      for (int c = 0; c < 64; ++c)
        if (sphere_map::disc_from_pixel(Vec2(c, r), 64, 64).squaredNorm() < 1 && (r + c) % 2)
          mv.rgb.at<cv::Vec3f>(r, c) = cv::Vec3f(1, 1, 1);
    set.views.push_back(mv);
  }
  const BlendEngine engine(set, views);
  double point_spread = 0, footprint_spread = 0;
  int count = 0;
  for (const Vec3& v : random_directions(10, 7))
    for (const Vec3& n0 : random_directions(20, 8)) {
      const Vec3 n = n0.dot(v) < 0.3 ? Vec3((n0 + v).normalized()) : n0;
      const ViewWeights located = engine.locate(v);
      const double point = engine.radiance(located, v, n).x();
      // Eight texels of a 64^2 map: 8 x 2/64 disc units; the normal moves about that much.
      const double wide = engine.radiance(located, v, n, footprint_of(n, 0.25)).x();
      point_spread += (point - 0.5) * (point - 0.5);
      footprint_spread += (wide - 0.5) * (wide - 0.5);
      ++count;
    }
  EXPECT_GT(std::sqrt(point_spread / count), 0.05);
  EXPECT_LT(std::sqrt(footprint_spread / count), 0.05);
}

Vec3 inside_first_triangle(const ViewSet& views) {
  const auto& t = views.triangles()[0];
  const auto& w = views.views();
  return (w[std::size_t(t[0])] + 0.8 * w[std::size_t(t[1])] + 0.9 * w[std::size_t(t[2])]).normalized();
}

// A set of two resolutions: every view but the sharp ones says it was measured at an eighth of the
// map size. Sharp views are red, blurry ones blue, so the result says whose detail was taken.
MapSet two_resolutions(const ViewSet& views, const std::vector<int>& sharp, int size, cv::Mat sharp_confidence = {}) {
  MapSet set;
  for (std::size_t i = 0; i < views.views().size(); ++i) {
    const bool is_sharp = std::find(sharp.begin(), sharp.end(), int(i)) != sharp.end();
    MapView mv;
    mv.view = views.views()[i];
    mv.world_from_view = world_from_view_for(mv.view);
    mv.warp = CentralDirection::Mirror;
    mv.source = MapSource::Captured;
    mv.rgb = testing::analytic_map([&](const Mat3&, const Vec2&) { return is_sharp ? Vec3(1, 0, 0) : Vec3(0, 0, 1); },
                                   mv.world_from_view, size, size);
    mv.confidence =
        is_sharp && !sharp_confidence.empty() ? sharp_confidence.clone() : cv::Mat(size, size, CV_32FC1, cv::Scalar(1));
    mv.attributes["nativeSize"] = std::to_string(is_sharp ? size : size / 8);
    set.views.push_back(mv);
  }
  return set;
}

TEST(MipMaskBlend, TheSharpSourceGivesTheDetailWhereItCoversAndTheBlendReturnsWhenCoarse) {
  const ViewSet views = ViewSet::named("icosa");
  // A direction inside a triangle; its first located view is the sharp one.
  const Vec3 v = inside_first_triangle(views);
  const ViewWeights probe_loc = ViewSet(views).locate(v);
  const int sharp = probe_loc.views[0];
  const MapSet set = two_resolutions(views, {sharp}, 64);
  const BlendEngine engine(set, views);
  ASSERT_TRUE(engine.mixed_resolution());
  EXPECT_EQ(engine.detail_level(sharp), 0.0);
  EXPECT_EQ(engine.detail_level(probe_loc.views[1]), 3.0);
  const ViewWeights located = engine.locate(v);
  const Vec3 n = (v + 0.1 * v.unitOrthogonal()).normalized();
  // At the point: the blurry sources' masks are 0 at level 0, the sharp one's 1: red only.
  const Vec3 point = engine.radiance(located, v, n);
  EXPECT_NEAR(point.x(), 1.0, 1e-5);
  EXPECT_NEAR(point.z(), 0.0, 1e-5);
  // At a footprint coarser than the blurry maps' detail level (3) their masks are 1 where they cover:
  // the plain blend, as the same set without native sizes gives it (within what the masks' coverage
  // at such coarse levels changes).
  MapSet plain_set = set;
  for (MapView& mv : plain_set.views) mv.attributes.erase("nativeSize");
  const BlendEngine plain(plain_set, views);
  ASSERT_FALSE(plain.mixed_resolution());
  const Vec3 coarse = engine.radiance(located, v, n, footprint_of(n, 0.3));
  EXPECT_NEAR(coarse.z(), plain.radiance(located, v, n, footprint_of(n, 0.3)).z(), 0.05);
  EXPECT_NEAR(coarse.x() + coarse.z(), 1.0, 1e-4);
  // In between, the blurry share rises over about one level of detail (a mask's ramp), with no jump:
  // footprints grow by 2^0.2 a step.
  double previous = 0;
  for (double size = 0.001; size < 0.7; size *= std::pow(2.0, 0.2)) {
    const double blue = engine.radiance(located, v, n, footprint_of(n, size)).z();
    if (size < 0.1) {
      EXPECT_LT(blue, 1e-3) << size;  // lod below 2: the sharp source alone
    }
    EXPECT_LE(std::abs(blue - previous), 0.25) << size;
    previous = blue;
  }
}

TEST(MipMaskBlend, WhereTheSharpSourceHasNoCoverageTheOthersFillIn) {
  const ViewSet views = ViewSet::named("icosa");
  const Vec3 v = inside_first_triangle(views);
  const int sharp = ViewSet(views).locate(v).views[0];
  // The sharp map's confidence is 0 on its left half.
  cv::Mat conf(64, 64, CV_32FC1, cv::Scalar(1));
  conf(cv::Rect(0, 0, 32, 64)) = 0.0f;
  const MapSet set = two_resolutions(views, {sharp}, 64, conf);
  const BlendEngine engine(set, views);
  const ViewWeights located = engine.locate(v);
  const Mat3 Ts = world_from_view_for(views.views()[std::size_t(sharp)]);
  // Normals whose mirror directions land left and right in the sharp map.
  auto normal_for = [&](double x) {
    const Vec3 r = Ts * sphere_map::g_mirror(Vec2(x, 0.1));
    return (r + v).normalized();  // the half vector: n with 2(n.v)n - v = r
  };
  const Vec3 left = engine.radiance(located, v, normal_for(-0.5)), right = engine.radiance(located, v, normal_for(0.5));
  EXPECT_NEAR(right.x(), 1.0, 1e-4);  // covered: the sharp source alone
  EXPECT_GT(left.z(), 0.5);           // uncovered: the blurry sources
}

TEST(MipMaskBlend, AMixedSetsMapIsItsRadianceAtEachTexelsFootprint) {
  const ViewSet views = ViewSet::named("icosa");
  const MapSet set = two_resolutions(views, {0, 3, 7}, 32);
  const BlendEngine engine(set, views);
  const Vec3 d = Vec3(0.3, 0.5, 0.8).normalized();
  const BlendResult b = engine.map(d, Vec3(0, 1, 0));
  for (int r = 2; r < 30; r += 5)
    for (int c = 2; c < 30; c += 5) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 32, 32);
      if (xy.squaredNorm() >= 1) continue;
      const Vec3 n = b.world_from_view * sphere_map::g_normal(xy);
      BlendEngine::Footprint fp;
      fp.dn_dx = b.world_from_view * sphere_map::g_normal(xy + Vec2(2.0 / 32, 0)) - n;
      fp.dn_dy = b.world_from_view * sphere_map::g_normal(xy - Vec2(0, 2.0 / 32)) - n;
      const Vec3 L = engine.radiance(b.located, d, n, fp);
      const cv::Vec3f o = b.rgb.at<cv::Vec3f>(r, c);
      EXPECT_NEAR(o[0], L.x(), 1e-6);
      EXPECT_NEAR(o[2], L.z(), 1e-6);
      EXPECT_TRUE(std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2]));
    }
}

TEST(MipMaskBlend, ABadNativeSizeIsRefusedNamingTheView) {
  const ViewSet views = ViewSet::named("icosa");
  MapSet set = analytic_map_set(views, 16, 16, "mirror", testing::mirror_texel);
  set.views[4].attributes["nativeSize"] = "-3";
  try {
    BlendEngine engine(set, views);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("view 4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nativeSize"), std::string::npos) << e.what();
  }
}

TEST(ResolutionMask, LevelsAreTheMinimumCoverageTimesTheResolutionRamp) {
  cv::Mat coverage(16, 16, CV_32FC1, cv::Scalar(1));
  coverage.at<float>(5, 6) = 0.25f;
  const auto mask = resolution_mask(coverage, 2.0);  // real detail from level 2
  ASSERT_EQ(mask->levels(), 5);
  EXPECT_EQ(mask->level(0).at<float>(0, 0), 0.0f);  // level 0: clamp(0 - 2 + 1) = 0
  EXPECT_EQ(mask->level(1).at<float>(0, 0), 0.0f);  // level 1: clamp(0) = 0
  EXPECT_EQ(mask->level(2).at<float>(0, 0), 1.0f);
  EXPECT_EQ(mask->level(2).at<float>(1, 1), 0.25f);  // covers (4..7, 4..7): the minimum
  EXPECT_EQ(mask->level(4).at<float>(0, 0), 0.25f);
  const auto half = resolution_mask(coverage, 1.5);
  EXPECT_EQ(half->level(1).at<float>(0, 0), 0.5f);  // clamp(1 - 1.5 + 1) = 0.5
  EXPECT_TRUE(mixed_resolution({0.0, 0.6}));
  EXPECT_FALSE(mixed_resolution({0.0, 0.5}));
  EXPECT_FALSE(mixed_resolution({}));
}

}  // namespace
}  // namespace rsibr
