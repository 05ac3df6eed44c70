// calib/orientation/pair_matches_picture.h: two views side by side at the asked height, an inlier's line in
// green and an outlier's in red, between the right pixels.
#include "calib/orientation/pair_matches_picture.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

TEST(PairMatchesPicture, ViewsSitSideBySideAndEachMatchIsDrawnInItsColourBetweenItsPixels) {
  const cv::Mat a(100, 200, CV_32FC3, cv::Scalar(0.2, 0.2, 0.2)), b(50, 50, CV_32FC3, cv::Scalar(0.2, 0.2, 0.2));
  PairOrientation p;
  p.matches_px = {{Vec2(20, 20), Vec2(10, 10)}, {Vec2(20, 80), Vec2(10, 40)}};
  p.match_inlier = {1, 0};
  const cv::Mat shown = pair_matches_picture(a, b, p, 200);
  // a scaled 2x (400 x 200), b 4x (200 x 200).
  ASSERT_EQ(shown.rows, 200);
  ASSERT_EQ(shown.cols, 600);
  ASSERT_EQ(shown.type(), CV_8UC3);
  // The inlier's line from (40, 40) to (440, 40): green at its middle; the outlier's from (40, 160)
  // to (440, 160): red.
  const cv::Vec3b g = shown.at<cv::Vec3b>(40, 240), r = shown.at<cv::Vec3b>(160, 240);
  EXPECT_GT(g[1], 150);
  EXPECT_LT(g[2], 120);
  EXPECT_GT(r[2], 150);
  EXPECT_LT(r[1], 120);
  EXPECT_THROW(pair_matches_picture(cv::Mat(), b, p), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
