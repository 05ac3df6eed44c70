#include "compare/compare_pictures.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

double lightness(const cv::Vec3b& bgr) { return 0.0722 * bgr[0] + 0.7152 * bgr[1] + 0.2126 * bgr[2]; }

TEST(ComparePictures, TheColourBarIsPerceptuallyOrdered) {
  const cv::Mat bar = colour_bar_bgr(256, 1);
  for (int c = 1; c < 256; ++c)
    EXPECT_GE(lightness(bar.at<cv::Vec3b>(0, c)) + 0.75, lightness(bar.at<cv::Vec3b>(0, c - 1))) << c;
  EXPECT_GT(lightness(bar.at<cv::Vec3b>(0, 255)), lightness(bar.at<cv::Vec3b>(0, 0)) + 100);
}

TEST(ComparePictures, HeatMapClampsAndMarksTexelsWithoutWeight) {
  cv::Mat e(1, 5, CV_32FC1);
  e.at<float>(0, 0) = 0;
  e.at<float>(0, 1) = 0.5f;
  e.at<float>(0, 2) = 1.f;
  e.at<float>(0, 3) = 7.f;  // beyond the scale: the top colour
  e.at<float>(0, 4) = 0.5f;
  cv::Mat w(1, 5, CV_32FC1, cv::Scalar(1));
  w.at<float>(0, 4) = 0;
  const cv::Mat h = heat_map_bgr(e, w, 1.0);
  const cv::Mat bar = colour_bar_bgr(256, 1);
  EXPECT_EQ(h.at<cv::Vec3b>(0, 0), bar.at<cv::Vec3b>(0, 0));
  EXPECT_EQ(h.at<cv::Vec3b>(0, 2), bar.at<cv::Vec3b>(0, 255));
  EXPECT_EQ(h.at<cv::Vec3b>(0, 3), bar.at<cv::Vec3b>(0, 255));
  EXPECT_EQ(h.at<cv::Vec3b>(0, 4), kNoWeightColour);
  EXPECT_GT(lightness(h.at<cv::Vec3b>(0, 1)), lightness(h.at<cv::Vec3b>(0, 0)));
  EXPECT_THROW(heat_map_bgr(e, w, 0.0), std::invalid_argument);
}

TEST(ComparePictures, HeatScaleIsARoundedQuantile) {
  cv::Mat e(10, 10, CV_32FC1);
  for (int i = 0; i < 100; ++i) e.at<float>(i / 10, i % 10) = 0.003f * float(i + 1);  // 0.003 .. 0.3
  const cv::Mat w(10, 10, CV_32FC1, cv::Scalar(1));
  EXPECT_DOUBLE_EQ(heat_scale_max({e}, {w}, 0.5), 0.2);                                     // median 0.15 -> 0.2
  EXPECT_DOUBLE_EQ(heat_scale_max({e}, {w}, 1.0), 0.5);                                     // 0.3 -> 0.5
  EXPECT_DOUBLE_EQ(heat_scale_max({cv::Mat(10, 10, CV_32FC1, cv::Scalar(0))}, {w}), 0.01);  // identical maps
}

TEST(ComparePictures, SideBySideHasThreePanelsAndAScaleBar) {
  SideBySideInput in;
  in.a_rgb = cv::Mat(8, 8, CV_32FC3, cv::Scalar(0.18, 0.18, 0.18));
  in.b_rgb = in.a_rgb.clone();
  in.error = cv::Mat(8, 8, CV_32FC1, cv::Scalar(0.25));
  in.weight = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1));
  in.heat_max = 0.5;
  in.title = "view.000";
  const cv::Mat out = side_by_side(in, 64);
  EXPECT_EQ(out.type(), CV_8UC3);
  EXPECT_GE(out.cols, 3 * 64);
  // The heat panel's centre holds the colour of 0.25 / 0.5 on the bar.
  const int panel = 64, gap = 6;
  const cv::Vec3b centre = out.at<cv::Vec3b>(44 + panel / 2, gap + 2 * (panel + gap) + panel / 2);
  EXPECT_EQ(centre, colour_bar_bgr(256, 1).at<cv::Vec3b>(0, 128));
  const cv::Mat sheet = contact_sheet({out, out, out}, 100);
  EXPECT_EQ(sheet.cols, 2 * (100 + gap) + gap);
  // A large map is shrunk to the panel limit.
  in.a_rgb = cv::Mat(40, 80, CV_32FC3, cv::Scalar(0.18, 0.18, 0.18));
  in.b_rgb = in.a_rgb.clone();
  in.error = cv::Mat(40, 80, CV_32FC1, cv::Scalar(0.25));
  in.weight = cv::Mat(40, 80, CV_32FC1, cv::Scalar(1));
  EXPECT_EQ(side_by_side(in, 8, 20).cols, 3 * 20 + 4 * gap);
}

}  // namespace
}  // namespace rsibr
