// The grey ball's cross-view consistency (calib/extraction/lambert_consensus.h): maps of one Lambertian ball
// from several views agree at every normal, except where one view alone is shadowed.
#include "calib/extraction/lambert_consensus.h"

#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// A smooth irradiance-like radiance of the world normal (brighter above and toward +X).
double radiance(const Vec3& n) { return 0.2 + 0.12 * (n.y() + 1) + 0.05 * (n.x() + 1); }

// A captured map of the ball seen from direction v (world), with radiance(n) at each texel.
MapView grey_view(const Vec3& v, int size = 48) {
  MapView mv;
  mv.world_from_view = world_from_view_for(v);
  mv.view = mv.world_from_view.col(2);
  mv.warp = CentralDirection::Normal;
  mv.source = MapSource::Captured;
  mv.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar::all(0));
  mv.confidence = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(x, y), size, size);
      if (xy.squaredNorm() >= 0.95) continue;
      const Vec3 n = mv.world_from_view * sphere_map::g_normal(xy);
      const float l = float(radiance(n));
      mv.rgb.at<cv::Vec3f>(y, x) = cv::Vec3f(l, l, l);
      mv.confidence.at<float>(y, x) = 1;
    }
  return mv;
}

std::vector<MapView> ring(int n) {
  std::vector<MapView> views;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n;
    views.push_back(grey_view(Vec3(std::sin(a), 0.25, std::cos(a))));
  }
  return views;
}

TEST(LambertConsensus, ConsistentViewsKeepEveryTexel) {
  std::vector<MapView> views = ring(6);
  std::vector<cv::Mat> before;
  for (const MapView& v : views) before.push_back(v.confidence.clone());
  const auto rep = mask_lambert_inconsistencies(views);
  for (std::size_t v = 0; v < views.size(); ++v) {
    EXPECT_GT(rep[v].judged, 200) << v;
    EXPECT_EQ(rep[v].masked, 0) << v;
    EXPECT_FALSE(rep[v].left_out);
    EXPECT_EQ(cv::norm(views[v].confidence, before[v], cv::NORM_INF), 0.0);
  }
}

// A shadow on one view's map (half a stop darker over a patch) is masked there and nowhere else.
TEST(LambertConsensus, AShadowInOneViewIsMaskedInThatViewOnly) {
  std::vector<MapView> views = ring(6);
  cv::Mat& rgb = views[2].rgb;
  int shadowed = 0;
  for (int y = 10; y < 24; ++y)
    for (int x = 14; x < 34; ++x)
      if (views[2].confidence.at<float>(y, x) > 0) rgb.at<cv::Vec3f>(y, x) *= 0.7f, ++shadowed;
  const auto rep = mask_lambert_inconsistencies(views);
  ASSERT_GT(shadowed, 100);
  EXPECT_FALSE(rep[2].left_out);
  int masked_in_patch = 0;
  for (int y = 10; y < 24; ++y)
    for (int x = 14; x < 34; ++x)
      masked_in_patch += views[2].confidence.at<float>(y, x) == 0 && rgb.at<cv::Vec3f>(y, x)[0] > 0;
  // The shadowed texels that two other views also see are masked (most of a patch facing the
  // view); texels outside the patch are not.
  EXPECT_EQ(rep[2].masked, masked_in_patch);
  EXPECT_GT(masked_in_patch, shadowed / 2);
  for (std::size_t v = 0; v < views.size(); ++v)
    if (v != 2) {
      EXPECT_EQ(rep[v].masked, 0) << v;
    }
}

// A view shadowed all over (the photographer between the sun and the ball) is left out, and its
// neighbours, judged again without it, keep their texels.
TEST(LambertConsensus, AViewShadowedAllOverIsLeftOut) {
  std::vector<MapView> views = ring(6);
  views[4].rgb *= 0.6;
  const auto rep = mask_lambert_inconsistencies(views);
  EXPECT_TRUE(rep[4].left_out);
  EXPECT_EQ(cv::countNonZero(views[4].confidence), 0);
  EXPECT_NEAR(rep[4].median_stops, std::log2(0.6), 0.02);
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (v != 4) {
      EXPECT_FALSE(rep[v].left_out) << v;
      EXPECT_EQ(rep[v].masked, 0) << v;
    }
  }
}

// Two views alone cannot out-vote each other: nothing is judged with min_others = 2.
TEST(LambertConsensus, TwoViewsAreNotJudged) {
  std::vector<MapView> views = ring(2);
  views[1].rgb *= 0.5;
  const auto rep = mask_lambert_inconsistencies(views);
  EXPECT_EQ(rep[0].judged, 0);
  EXPECT_EQ(rep[1].judged, 0);
  EXPECT_FALSE(rep[1].left_out);
}

}  // namespace
}  // namespace rsibr
