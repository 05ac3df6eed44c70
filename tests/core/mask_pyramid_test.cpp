#include "core/mask_pyramid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// An author whose levels are unrelated to each other (no level is the average of the one below).
float authored(int level, int col, int row) { return float((level * 7 + col * 3 + row * 5) % 11) / 10.0f; }

TEST(MaskPyramid, EachLevelIsExactlyTheAuthoredMask) {
  const MaskPyramid p(37, 20, authored);
  ASSERT_EQ(p.levels(), 6);  // 37x20, 18x10, 9x5, 4x2, 2x1, 1x1
  for (int l = 0; l < p.levels(); ++l) {
    const cv::Mat& m = p.level(l);
    EXPECT_EQ(m.cols, std::max(1, 37 >> l));
    EXPECT_EQ(m.rows, std::max(1, 20 >> l));
    for (int r = 0; r < m.rows; ++r)
      for (int c = 0; c < m.cols; ++c) EXPECT_EQ(m.at<float>(r, c), authored(l, c, r)) << l << " " << c << " " << r;
  }
}

TEST(MaskPyramid, AuthoredValuesAreClampedToTheUnitIntervalAndNanIsZero) {
  const MaskPyramid p(4, 4, [](int l, int c, int) { return c == 0 ? -1.0f : c == 1 ? 2.0f : c == 2 ? NAN : 0.5f; });
  EXPECT_EQ(p.level(0).at<float>(0, 0), 0.0f);
  EXPECT_EQ(p.level(0).at<float>(0, 1), 1.0f);
  EXPECT_EQ(p.level(0).at<float>(0, 2), 0.0f);
  EXPECT_EQ(p.level(0).at<float>(0, 3), 0.5f);
}

TEST(MaskPyramid, SamplesAtTexelCentresOfWholeLevelsAreTheTexels) {
  const MaskPyramid p(32, 32, authored);
  for (int l = 0; l < p.levels(); ++l) {
    const int s = 1 << l;
    for (int r = 0; r < p.level(l).rows; ++r)
      for (int c = 0; c < p.level(l).cols; ++c) {
        const Vec2 centre((c + 0.5) * s - 0.5, (r + 0.5) * s - 0.5);
        EXPECT_NEAR(p.sample(centre, l), authored(l, c, r), 1e-6);
      }
  }
}

TEST(MaskPyramid, TrilinearSamplingIsContinuousInTheLevelOfDetail) {
  const MaskPyramid p(64, 64, authored);
  const Vec2 at(20.3, 41.7);
  float previous = p.sample(at, 0.0);
  for (double lod = 0.01; lod <= 6.0; lod += 0.01) {
    const float v = p.sample(at, lod);
    EXPECT_LE(std::abs(v - previous), 0.02f) << lod;  // at most |difference of levels| x 0.01
    previous = v;
  }
  EXPECT_EQ(p.sample(at, -3.0), p.sample(at, 0.0));
  EXPECT_EQ(p.sample(at, 100.0), p.sample(at, double(p.levels() - 1)));
  EXPECT_EQ(p.sample(at, NAN), p.sample(at, 0.0));
}

TEST(MaskPyramid, FootprintsTileTheBaseAtEveryLevel) {
  const MaskPyramid p(37, 20, authored);
  for (int l = 0; l < p.levels(); ++l) {
    cv::Mat count(20, 37, CV_32SC1, cv::Scalar(0));
    for (int r = 0; r < p.level(l).rows; ++r)
      for (int c = 0; c < p.level(l).cols; ++c) count(p.footprint(l, c, r)) += 1;
    double lo, hi;
    cv::minMaxLoc(count, &lo, &hi);
    EXPECT_EQ(lo, 1) << l;
    EXPECT_EQ(hi, 1) << l;
  }
}

TEST(MaskPyramid, ConstantMasksSampleConstantEverywhere) {
  const MaskPyramid p(16, 8, [](int, int, int) { return 0.25f; });
  for (double x : {-5.0, 0.0, 7.5, 15.0, 40.0})
    for (double lod : {0.0, 0.5, 2.2, 9.0}) EXPECT_FLOAT_EQ(p.sample(Vec2(x, 3.3), lod), 0.25f);
  EXPECT_THROW(MaskPyramid(0, 4, authored), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
