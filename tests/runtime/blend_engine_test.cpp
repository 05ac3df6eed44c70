#include "runtime/blend_engine.h"

#include "analytic_map_set.h"
#include "core/albedo_normalisation.h"
#include "core/sphere_map.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

using namespace rsibr::testing;

// The lookup at (v = d, n = T_d g_normal(p)) must be blend()'s texel p, for every texel, both warps,
// views at a source, inside triangles and on edges.
TEST(BlendEngine, LookupEqualsBlendAtTheDestinationView) {
  const ViewSet views = ViewSet::icosahedron();
  std::vector<Vec3> dests = random_directions(4, 11);
  dests.push_back(views.views()[3]);  // at a source
  const auto& t0 = views.triangles()[0];
  dests.push_back((views.views()[std::size_t(t0[0])] + views.views()[std::size_t(t0[1])]).normalized());  // on an edge
  for (const auto& [warp, f] :
       {std::pair{"mirror", TexelFunction(fresnel_mirror_texel)}, std::pair{"normal", TexelFunction(lambert_texel)}}) {
    const MapSet set = analytic_map_set(views, 32, 32, warp, f);
    const BlendEngine lookup(set, views);
    for (const Vec3& d : dests) {
      const BlendResult b = blend(set, views, d, Vec3(0, 1, 0));
      int checked = 0;
      for (int r = 0; r < 32; ++r)
        for (int c = 0; c < 32; ++c) {
          const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 32, 32);
          if (xy.squaredNorm() > 1.0) continue;
          const Vec3 n = b.world_from_view * sphere_map::g_normal(xy);
          double w = -1;
          const Vec3 L = lookup.radiance(d.normalized(), n, &w);
          const cv::Vec3f o = b.rgb.at<cv::Vec3f>(r, c);
          for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(L[k], o[k], 1e-6 * std::max(1.0, std::abs(double(o[k])))) << warp << " texel " << c << "," << r;
          ASSERT_NEAR(w, b.weight.at<float>(r, c), 1e-6) << warp << " texel " << c << "," << r;
          ++checked;
        }
      EXPECT_GT(checked, 700);
    }
  }
}

// Albedo-normalised sets: both scale by A(n.v) (blend per destination texel, the lookup per call).
TEST(BlendEngine, LookupEqualsBlendForAlbedoNormalisedMaps) {
  const ViewSet views = ViewSet::icosahedron();
  MapSet set = analytic_map_set(views, 24, 24, "mirror", fresnel_mirror_texel);
  std::vector<float> table;
  for (int k = 0; k < 8; ++k) table.insert(table.end(), {0.1f + 0.1f * float(k), 1.0f - 0.1f * float(k), 0.5f});
  for (MapView& v : set.views) v.albedo = table;
  const BlendEngine lookup(set, views);
  const Vec3 d = Vec3(-0.3, 0.5, 0.6).normalized();
  const BlendResult b = blend(set, views, d, Vec3(0, 1, 0));
  MapSet plain = set;
  for (MapView& v : plain.views) v.albedo.clear();
  const BlendResult p = blend(plain, views, d, Vec3(0, 1, 0));
  for (int r = 0; r < 24; ++r)
    for (int c = 0; c < 24; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 24, 24);
      if (xy.squaredNorm() > 1.0) continue;
      const Vec3 A = albedo_at(table, float(sphere_map::g_normal(xy).z()));
      const Vec3 L = lookup.radiance(d, b.world_from_view * sphere_map::g_normal(xy));
      for (int k = 0; k < 3; ++k) {
        const double o = b.rgb.at<cv::Vec3f>(r, c)[k];
        ASSERT_NEAR(o, A[k] * p.rgb.at<cv::Vec3f>(r, c)[k], 1e-6 * std::max(1.0, std::abs(o)));
        ASSERT_NEAR(L[k], o, 1e-5 * std::max(1.0, std::abs(o))) << "texel " << c << "," << r;
      }
    }
}

// Same with confidence channels (captured maps): the confidence multiplies the weights identically.
TEST(BlendEngine, LookupEqualsBlendWithConfidence) {
  const ViewSet views = ViewSet::icosahedron();
  MapSet set = analytic_map_set(views, 24, 24, "mirror", mirror_texel);
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    set.views[i].confidence = cv::Mat(24, 24, CV_32FC1);
    for (int r = 0; r < 24; ++r)
      for (int c = 0; c < 24; ++c)
        set.views[i].confidence.at<float>(r, c) = float(0.2 + 0.8 * ((r * 7 + c * 3 + int(i)) % 5) / 4.0);
  }
  const BlendEngine lookup(set, views);
  const Vec3 d = Vec3(0.2, -0.4, 0.7).normalized();
  const BlendResult b = blend(set, views, d, Vec3(0, 1, 0));
  for (int r = 0; r < 24; ++r)
    for (int c = 0; c < 24; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 24, 24);
      if (xy.squaredNorm() > 1.0) continue;
      const Vec3 L = lookup.radiance(d, b.world_from_view * sphere_map::g_normal(xy));
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(L[k], b.rgb.at<cv::Vec3f>(r, c)[k], 1e-6);
    }
}

TEST(BlendEngine, HintedLocateEqualsViewSetLocate) {
  const std::vector<ViewSet> sets{ViewSet::icosahedron(), ViewSet::geodesic(1)};
  for (const ViewSet& views : sets) {
    const MapSet set = analytic_map_set(views, 8, 8, "mirror", mirror_texel);
    const BlendEngine lookup(set, views);
    int hint = -1;
    // A slowly turning direction (the hint is reused) and random jumps, plus the views themselves.
    std::vector<Vec3> dirs;
    for (int i = 0; i < 400; ++i)
      dirs.push_back(Vec3(std::cos(0.01 * i), 0.3 * std::sin(0.013 * i), std::sin(0.01 * i)));
    for (const Vec3& v : random_directions(200, 5)) dirs.push_back(v);
    for (const Vec3& v : views.views()) dirs.push_back(v);
    for (const Vec3& v : dirs) {
      const ViewWeights a = lookup.locate(v, &hint), b = views.locate(v);
      ASSERT_EQ(a.count, b.count);
      ASSERT_EQ(a.triangle, b.triangle);
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(a.views[std::size_t(k)], b.views[std::size_t(k)]);
        ASSERT_EQ(a.weights[std::size_t(k)], b.weights[std::size_t(k)]);  // bitwise
      }
    }
  }
}

// n.v < 0 (a shading normal past the silhouette) reads the nearest rim normal.
TEST(BlendEngine, NormalsFacingAwayTakeTheNearestRimNormal) {
  const ViewSet views = ViewSet::icosahedron();
  for (const char* warp : {"mirror", "normal"}) {
    const MapSet set =
        analytic_map_set(views, 32, 32, warp,
                         std::string(warp) == "mirror" ? TexelFunction(mirror_texel) : TexelFunction(lambert_texel));
    const BlendEngine lookup(set, views);
    const Vec3 v = Vec3(0.3, 0.5, 0.8).normalized();
    for (const Vec3& n : random_directions(50, 3)) {
      if (n.dot(v) >= 0) continue;
      const Vec3 rim = (n - n.dot(v) * v).normalized();
      const Vec3 a = lookup.radiance(v, n), b = lookup.radiance(v, rim);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-12) << warp;
    }
    const Vec3 behind = lookup.radiance(v, -v);
    EXPECT_TRUE(behind.allFinite()) << warp;
  }
}

// A set covering only the upper hemisphere, queried from everywhere: finite, within the maps' range.
TEST(BlendEngine, FiniteAndBoundedOutsideANonSurroundingSet) {
  std::vector<Vec3> up;
  const ViewSet all = ViewSet::geodesic(1);  // named: views() refers into it
  for (const Vec3& v : all.views())
    if (v.y() > 0.2) up.push_back(v);
  const ViewSet views(up);
  ASSERT_FALSE(views.surrounds());
  const MapSet set = analytic_map_set(views, 32, 32, "mirror", fresnel_mirror_texel);
  double lo = 1e300, hi = -1e300;
  for (const MapView& m : set.views) {
    double l, h;
    cv::minMaxLoc(m.rgb.reshape(1), &l, &h);
    lo = std::min(lo, l);
    hi = std::max(hi, h);
  }
  const BlendEngine lookup(set, views);
  const std::vector<Vec3> vs = random_directions(60, 8), ns = random_directions(60, 9);
  for (const Vec3& v : vs)
    for (const Vec3& n : ns) {
      double w = -1;
      const Vec3 L = lookup.radiance(v, n, &w);
      ASSERT_TRUE(L.allFinite());
      ASSERT_TRUE(w >= 0 && w <= 1);
      for (int k = 0; k < 3; ++k) {  // a convex combination, in float
        ASSERT_GE(L[k], lo - 1e-6 * std::abs(lo));
        ASSERT_LE(L[k], hi + 1e-6 * std::abs(hi));
      }
    }
}

// A caller that blends every frame keeps one BlendResult: map() into it must give a fresh map()'s
// bits whatever the kept result held before (another view, another size, source weights or not).
TEST(BlendEngine, MapIntoAKeptResultEqualsAFreshMap) {
  const ViewSet views = ViewSet::icosahedron();
  const MapSet set = analytic_map_set(views, 32, 32, "mirror", fresnel_mirror_texel);
  const BlendEngine engine(set, views);
  const std::vector<Vec3> dests = random_directions(4, 21);
  const auto same = [](const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
  };
  BlendResult kept;
  for (std::size_t i = 0; i < dests.size(); ++i) {
    MapRequest request;
    request.width = request.height = i == 2 ? 48 : 32;
    request.source_weights = i % 2 == 1;
    engine.map(dests[i], Vec3(0, 1, 0), request, kept);
    const BlendResult fresh = engine.map(dests[i], Vec3(0, 1, 0), request);
    EXPECT_TRUE(same(kept.rgb, fresh.rgb)) << "destination " << i;
    EXPECT_TRUE(same(kept.weight, fresh.weight)) << "destination " << i;
    EXPECT_TRUE(kept.world_from_view == fresh.world_from_view);
    EXPECT_EQ(kept.located.views, fresh.located.views);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(kept.source_weight[std::size_t(k)].empty(), !request.source_weights);
      if (request.source_weights) {
        EXPECT_TRUE(same(kept.source_weight[std::size_t(k)], fresh.source_weight[std::size_t(k)]));
      }
    }
  }
}

TEST(BlendEngine, RejectsAViewSetThatIsNotTheMapSets) {
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 8, 8, "mirror", mirror_texel);
  const ViewSet other = ViewSet::geodesic(1);
  EXPECT_THROW(BlendEngine(set, other), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
