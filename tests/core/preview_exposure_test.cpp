// The metering of every PNG preview (core/preview_exposure.h).
#include "core/preview_exposure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace rsibr {
namespace {

TEST(PreviewExposure, TheMedianLuminanceLandsOnMidGrey) {
  const cv::Mat grey(40, 60, CV_32FC3, cv::Scalar::all(0.72));
  EXPECT_NEAR(preview_exposure(grey), -2.0, 1e-6);
  // Luminance, not the channel mean: pure green of 0.18 / 0.7152 is mid-grey already.
  const cv::Mat green(10, 10, CV_32FC3, cv::Scalar(0, 0.18 / 0.7152, 0));
  EXPECT_NEAR(preview_exposure(green), 0.0, 1e-6);
}

// A sun of 10^6 on 1% of the picture moves a mean-based exposure by about 13 stops; the median
// does not move, so the rest of the scene stays readable.
TEST(PreviewExposure, ASunOrALampDoesNotDarkenThePicture) {
  cv::Mat scene(100, 100, CV_32FC3, cv::Scalar::all(0.09));
  scene(cv::Rect(0, 0, 10, 10)).setTo(cv::Scalar::all(1e6));
  EXPECT_NEAR(preview_exposure(scene), 1.0, 1e-6);
}

TEST(PreviewExposure, LargeUnitsAreNotShownWhite) {
  const cv::Mat merged(20, 20, CV_32FC3, cv::Scalar::all(180.0));  // an HDR merge's X/e
  EXPECT_NEAR(std::exp2(preview_exposure(merged)) * 180.0, 0.18, 1e-6);
}

TEST(PreviewExposure, OnlyPixelsThatHoldLightAreMetered) {
  // A sphere map: the corners outside the disc (alpha 0) and black or non-finite texels do not count.
  cv::Mat rgba(20, 20, CV_32FC4, cv::Scalar(0.36, 0.36, 0.36, 1));
  rgba(cv::Rect(0, 0, 20, 8)).setTo(cv::Scalar(5, 5, 5, 0));
  rgba.at<cv::Vec4f>(15, 15) = cv::Vec4f(std::numeric_limits<float>::quiet_NaN(), 0, 0, 1);
  rgba(cv::Rect(0, 16, 20, 4)).setTo(cv::Scalar(0, 0, 0, 1));
  EXPECT_NEAR(preview_exposure(rgba), -1.0, 1e-6);
  // A mask leaves out what it says (e.g. clipped pixels).
  cv::Mat rgb(10, 10, CV_32FC3, cv::Scalar::all(0.18));
  rgb(cv::Rect(0, 0, 10, 6)).setTo(cv::Scalar::all(100));
  cv::Mat mask(10, 10, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(0, 0, 10, 6)).setTo(0);
  EXPECT_NEAR(preview_exposure(rgb, mask), 0.0, 1e-6);
}

TEST(PreviewExposure, NothingToMeterGivesZeroAndBadInputIsAnError) {
  EXPECT_EQ(preview_exposure(cv::Mat(8, 8, CV_32FC3, cv::Scalar::all(0))), 0.f);
  EXPECT_EQ(preview_exposure(cv::Mat()), 0.f);
  EXPECT_THROW(preview_exposure(cv::Mat(8, 8, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(preview_exposure(cv::Mat(8, 8, CV_32FC3, cv::Scalar::all(1)), cv::Mat(4, 4, CV_8UC1)),
               std::invalid_argument);
}

TEST(PreviewExposure, PanelsShownTogetherAreMeteredTogether) {
  const cv::Mat dark(10, 10, CV_32FC3, cv::Scalar::all(0.045)), bright(10, 30, CV_32FC3, cv::Scalar::all(0.72));
  EXPECT_NEAR(preview_exposure(std::vector<cv::Mat>{dark, bright}), -2.0,
              1e-6);  // 300 of 400 pixels are the bright panel
  // Large pictures are read on a grid: the same answer as every pixel for a smooth image.
  cv::Mat big(2048, 1024, CV_32FC3);
  for (int y = 0; y < big.rows; ++y) big.row(y).setTo(cv::Scalar::all(0.01 + 0.001 * y));
  EXPECT_NEAR(preview_exposure(big), std::log2(0.18 / (0.01 + 0.001 * 1024)), 0.01);
}

}  // namespace
}  // namespace rsibr
