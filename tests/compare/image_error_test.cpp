#include "compare/image_error.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

cv::Mat rgb(int w, int h, std::initializer_list<float> values) {
  cv::Mat m(h, w, CV_32FC3);
  auto it = values.begin();
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      for (int k = 0; k < 3; ++k) m.ptr<float>(r)[3 * c + k] = *it++;
  return m;
}

TEST(ImageError, IdenticalImagesGiveZeroErrorAndTheCappedPsnr) {
  cv::Mat a(4, 4, CV_32FC3, cv::Scalar(0.5, 2.0, 1e4));
  a.at<cv::Vec3f>(1, 2) = cv::Vec3f(0, 0, 0);  // black texels: the log stays finite through eps
  const cv::Mat w(4, 4, CV_32FC1, cv::Scalar(1));
  ErrorSettings s{1e-3, 1e4};
  const ErrorMetrics m = error_metrics(error_sums(a, a.clone(), w, s), s);
  EXPECT_EQ(m.relative_rms, 0.0);
  EXPECT_EQ(m.log_rms_stops, 0.0);
  EXPECT_EQ(m.mse, 0.0);
  EXPECT_TRUE(m.psnr_capped);
  EXPECT_DOUBLE_EQ(m.psnr_db, kPsnrCapDb);
  EXPECT_TRUE(std::isfinite(m.psnr_db));
  const cv::Mat e = log_error_image(a, a, w, 1e-3);
  EXPECT_EQ(cv::countNonZero(e), 0);
}

TEST(ImageError, AllBlackIdenticalImagesAreFinite) {
  const cv::Mat a(3, 3, CV_32FC3, cv::Scalar(0, 0, 0));
  const cv::Mat w(3, 3, CV_32FC1, cv::Scalar(1));
  ErrorSettings s{1e-6, 1.0};
  const ErrorMetrics m = error_metrics(error_sums(a, a, w, s), s);
  EXPECT_EQ(m.relative_rms, 0.0);
  EXPECT_EQ(m.log_rms_stops, 0.0);
  EXPECT_DOUBLE_EQ(m.psnr_db, kPsnrCapDb);
}

// Two texels, weights 1 and 3, worked by hand:
//   texel 0: a = (2, 1, 1), b = (1, 1, 1), w = 1;  texel 1: a = (0, 4, 1), b = (0, 2, 1), w = 3
//   squared error = 1*(1) + 3*(4) = 13; squared reference = 1*3 + 3*(0+4+1) = 18
//   relative RMS = sqrt(13/18); MSE = 13 / (3*4) = 13/12; PSNR(peak 4) = 10 log10(16 / (13/12))
//   with eps = 1 the log2 ratios are log2(3/2), 0, 0 | 0, log2(5/3), 0:
//   log RMS = sqrt((1*log2(1.5)^2 + 3*log2(5/3)^2) / 12)
TEST(ImageError, MetricsMatchAHandComputationOnATinyMap) {
  const cv::Mat a = rgb(2, 1, {2, 1, 1, 0, 4, 1});
  const cv::Mat b = rgb(2, 1, {1, 1, 1, 0, 2, 1});
  cv::Mat w(1, 2, CV_32FC1);
  w.at<float>(0, 0) = 1;
  w.at<float>(0, 1) = 3;
  ErrorSettings s{1.0, 4.0};
  const ErrorMetrics m = error_metrics(error_sums(a, b, w, s), s);
  EXPECT_NEAR(m.relative_rms, std::sqrt(13.0 / 18.0), 1e-12);
  EXPECT_NEAR(m.mse, 13.0 / 12.0, 1e-12);
  EXPECT_NEAR(m.psnr_db, 10 * std::log10(16.0 / (13.0 / 12.0)), 1e-9);
  EXPECT_FALSE(m.psnr_capped);
  const double l1 = std::log2(1.5), l2 = std::log2(5.0 / 3.0);
  EXPECT_NEAR(m.log_rms_stops, std::sqrt((l1 * l1 + 3 * l2 * l2) / 12), 1e-12);
  EXPECT_EQ(m.texels, 2);
  EXPECT_DOUBLE_EQ(m.weight, 4.0);
  EXPECT_NEAR(m.mean_a[1], (1 + 3 * 4) / 4.0, 1e-12);
  const cv::Mat e = log_error_image(a, b, w, 1.0);
  EXPECT_NEAR(e.at<float>(0, 0), std::sqrt(l1 * l1 / 3), 1e-6);
  EXPECT_NEAR(e.at<float>(0, 1), std::sqrt(l2 * l2 / 3), 1e-6);
}

TEST(ImageError, ZeroWeightTexelsDoNotCount) {
  cv::Mat a = rgb(2, 1, {1, 1, 1, 1e30f, -5, 7});
  a.at<cv::Vec3f>(0, 1)[0] = NAN;  // even a NaN behind zero weight is ignored
  const cv::Mat b = rgb(2, 1, {1, 1, 1, 0, 0, 0});
  cv::Mat w(1, 2, CV_32FC1);
  w.at<float>(0, 0) = 1;
  w.at<float>(0, 1) = 0;
  ErrorSettings s{1e-3, 1.0};
  const ErrorMetrics m = error_metrics(error_sums(a, b, w, s), s);
  EXPECT_EQ(m.relative_rms, 0.0);
  EXPECT_EQ(m.texels, 1);
  EXPECT_EQ(log_error_image(a, b, w, 1e-3).at<float>(0, 1), 0.f);
}

TEST(ImageError, PoolingSumsNumeratorsAndDenominators) {
  const cv::Mat a1 = rgb(1, 1, {2, 2, 2}), b1 = rgb(1, 1, {1, 1, 1});
  const cv::Mat a2 = rgb(1, 1, {3, 3, 3}), b2 = rgb(1, 1, {3, 3, 3});
  const cv::Mat w(1, 1, CV_32FC1, cv::Scalar(1));
  ErrorSettings s{1e-3, 3.0};
  ErrorSums pooled = error_sums(a1, b1, w, s);
  pooled.merge(error_sums(a2, b2, w, s));
  // (3 * 1) / (3 * 1 + 3 * 9)
  EXPECT_NEAR(error_metrics(pooled, s).relative_rms, std::sqrt(3.0 / 30.0), 1e-12);
}

TEST(ImageError, NoWeightOrNoReferenceIsAnError) {
  const cv::Mat a(2, 2, CV_32FC3, cv::Scalar(1, 1, 1)), zero(2, 2, CV_32FC3, cv::Scalar(0, 0, 0));
  ErrorSettings s;
  EXPECT_THROW(error_metrics(error_sums(a, a, cv::Mat(2, 2, CV_32FC1, cv::Scalar(0)), s), s), std::invalid_argument);
  EXPECT_THROW(error_metrics(error_sums(a, zero, cv::Mat(2, 2, CV_32FC1, cv::Scalar(1)), s), s), std::invalid_argument);
  EXPECT_THROW(error_sums(a, cv::Mat(3, 2, CV_32FC3), cv::Mat(2, 2, CV_32FC1), s), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
