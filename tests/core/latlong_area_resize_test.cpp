#include "core/latlong_area_resize.h"

#include "core/latlong_ripmap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

EnvMap random_latlong(int w, int h, std::uint32_t seed) {
  EnvMap m = EnvMap::zeros(Layout(LayoutKind::LatLong, w, h), 3);
  std::mt19937 rng(seed);
  std::exponential_distribution<float> e(1.f);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) m.pixels.at<cv::Vec3f>(r, c) = cv::Vec3f(e(rng), e(rng), 1e4f * e(rng) * (c == 3));
  return m;
}

TEST(LatLongAreaResize, KeepsTheIntegralExactlyAtAnySize) {
  const EnvMap src = random_latlong(64, 33, 5);
  const std::vector<double> before = integral(src);
  for (const auto& [w, h] : {std::pair{8, 5}, {33, 17}, {65, 33}, {100, 51}, {2, 2}, {257, 129}, {64, 33}}) {
    const std::vector<double> after = integral(latlong_area_resize(src, w, h));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(after[std::size_t(k)], before[std::size_t(k)], 1e-6 * before[std::size_t(k)]) << w << "x" << h;
  }
}

TEST(LatLongAreaResize, SameSizeIsTheIdentityAndAConstantStaysConstant) {
  const EnvMap src = random_latlong(40, 21, 9);
  EXPECT_LE(cv::norm(latlong_area_resize(src, 40, 21).pixels, src.pixels, cv::NORM_INF), 1e-5 * 1e4);
  EnvMap flat = EnvMap::zeros(Layout(LayoutKind::LatLong, 50, 25), 3);
  flat.pixels.setTo(cv::Scalar(0.25, 2, 7));
  const EnvMap out = latlong_area_resize(flat, 17, 9);
  for (int r = 0; r < out.pixels.rows; ++r)
    for (int c = 0; c < out.pixels.cols; ++c) {
      const cv::Vec3f v = out.pixels.at<cv::Vec3f>(r, c);
      ASSERT_NEAR(v[0], 0.25f, 1e-6f);
      ASSERT_NEAR(v[2], 7.f, 3e-6f);
    }
}

TEST(LatLongRipmap, EveryLevelKeepsEachRowsIntegralAndTexelsNearSquare) {
  const EnvMap src = random_latlong(513, 257, 3);
  const LatLongRipmap ripmap(src);
  ASSERT_GT(ripmap.levels(), 5);
  for (int j = 1; j < ripmap.levels(); ++j) {
    const cv::Mat& level = ripmap.level(j);
    EXPECT_EQ(level.rows, 257);
    for (int r : {0, 100, 128, 256}) {
      // A row's integral over longitude: seam columns own half a column.
      const auto row_sum = [](const cv::Mat& m, int r) {
        double s = 0;
        for (int c = 0; c < m.cols; ++c) s += m.at<cv::Vec3f>(r, c)[0] * ((c == 0 || c == m.cols - 1) ? 0.5 : 1.0);
        return s / (m.cols - 1);
      };
      EXPECT_NEAR(row_sum(level, r), row_sum(src.pixels, r), 1e-5 * row_sum(src.pixels, r)) << "level " << j;
    }
  }
  // At the equator level 0; toward a pole coarser levels whose texels are about square.
  EXPECT_EQ(ripmap.level_for_latitude(0.0), 0);
  for (double degrees : {60.0, 80.0, 89.0}) {
    const double phi = degrees * kPi / 180;
    const int j = ripmap.level_for_latitude(phi);
    const double wide = ripmap.longitude_step(j) * std::cos(phi);
    EXPECT_LE(wide, ripmap.latitude_step() * (1 + 1e-12)) << degrees;
    if (j + 1 < ripmap.levels()) {
      EXPECT_GT(ripmap.longitude_step(j + 1) * std::cos(phi), ripmap.latitude_step());
    }
  }
}

}  // namespace
}  // namespace rsibr
