#include "compare/gain_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

// B: a smooth HDR-ish image (values over two decades); A = B / gains.
cv::Mat reference_image(int n) {
  cv::Mat b(n, n, CV_32FC3);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double u = double(c) / n, v = double(r) / n;
      b.at<cv::Vec3f>(r, c) = cv::Vec3f(float(0.05 + 4 * u * u), float(0.1 + 2 * v), float(0.02 + u * v * 8));
    }
  return b;
}

// The analytic Jacobian against central differences (separate from the value checks below).
TEST(GainFit, ResidualJacobianMatchesFiniteDifferences) {
  const double a[3] = {0.3, 2.5, 0.0}, b[3] = {0.7, 1.0, 0.2};
  for (const double eps : {1e-3, 0.5})
    for (const double t0 : {-2.0, 0.0, 1.5}) {
      const double theta[3] = {t0, 0.3 - t0, 0.1};
      double r[3], jac[9];
      log_gain_residuals(theta, a, b, eps, r, jac);
      const double h = 1e-6;
      for (int k = 0; k < 3; ++k) {
        double tp[3] = {theta[0], theta[1], theta[2]}, tm[3] = {theta[0], theta[1], theta[2]};
        tp[k] += h;
        tm[k] -= h;
        double rp[3], rm[3];
        log_gain_residuals(tp, a, b, eps, rp, nullptr);
        log_gain_residuals(tm, a, b, eps, rm, nullptr);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(jac[3 * c + k], (rp[c] - rm[c]) / (2 * h), 1e-8) << c << k;
      }
      EXPECT_NEAR(r[0], std::log(std::exp(t0) * 0.3 + eps) - std::log(0.7 + eps), 1e-15);
      EXPECT_TRUE(std::isfinite(r[2]));  // a = 0: the residual is finite through eps
    }
}

TEST(GainFit, RecoversAKnownGainExactlyOnNoiselessData) {
  const std::array<double, 3> truth{1.7, 0.6, 2.9};
  const cv::Mat b = reference_image(32);
  const cv::Mat a = apply_gains(b, {1 / truth[0], 1 / truth[1], 1 / truth[2]});
  GainFitOptions o;
  o.log_epsilon = 1e-3;
  const GainFit fit = fit_gains({{a, b, cv::Mat(32, 32, CV_32FC1, cv::Scalar(1))}}, o);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fit.gains[std::size_t(c)] / truth[std::size_t(c)], 1.0, 1e-6) << c;
  const double y = 0.2126 * truth[0] + 0.7152 * truth[1] + 0.0722 * truth[2];
  EXPECT_NEAR(fit.exposure_stops, std::log2(y), 1e-6);
  EXPECT_NEAR(fit.chroma[1], truth[1] / y, 1e-6);
  EXPECT_EQ(fit.texels_used, 32 * 32);
}

// 2 % multiplicative noise on every texel and 5 % outliers (B a sun at 1000x, or A a dark camera
// reflection): the robust fit stays within 1 % of the truth; a plain least-squares fit
// (loss scale huge) would not, which the test checks too so that it can fail.
TEST(GainFit, RecoversAKnownGainWithNoiseAndOutliers) {
  const std::array<double, 3> truth{2.0, 1.25, 0.8};
  const int n = 64;
  cv::Mat b = reference_image(n);
  cv::Mat a = apply_gains(b, {1 / truth[0], 1 / truth[1], 1 / truth[2]});
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      cv::Vec3f& pa = a.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) pa[k] *= 1 + noise(rng);
      const float x = u(rng);
      if (x < 0.03f)
        b.at<cv::Vec3f>(r, c) *= 1000.f;  // a sun clipped in A
      else if (x < 0.05f)
        pa *= 0.05f;  // the camera's dark reflection in A
    }
  const cv::Mat w(n, n, CV_32FC1, cv::Scalar(1));
  GainFitOptions o;
  o.log_epsilon = 1e-3;
  const GainFit fit = fit_gains({{a, b, w}}, o);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fit.gains[std::size_t(c)] / truth[std::size_t(c)], 1.0, 0.01) << c;
  EXPECT_TRUE(std::isfinite(fit.final_cost));

  o.loss_scale = 1e6;  // effectively squared loss: the outliers pull it away
  const GainFit plain = fit_gains({{a, b, w}}, o);
  EXPECT_GT(std::abs(plain.gains[0] / truth[0] - 1), 0.05);
}

TEST(GainFit, ZeroWeightTexelsDoNotEnterTheFit) {
  const cv::Mat b = reference_image(16);
  cv::Mat a = apply_gains(b, {0.5, 0.5, 0.5});
  cv::Mat w(16, 16, CV_32FC1, cv::Scalar(1));
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 8; ++c) {
      a.at<cv::Vec3f>(r, c) = cv::Vec3f(100, 0, 7);  // garbage, but zero confidence
      w.at<float>(r, c) = 0;
    }
  const GainFit fit = fit_gains({{a, b, w}}, GainFitOptions{});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fit.gains[std::size_t(c)], 2.0, 1e-6);
  EXPECT_EQ(fit.texels_used, 16 * 8);
}

TEST(GainFit, SubsamplingIsDeterministicAndBounded) {
  const cv::Mat b = reference_image(64);
  const cv::Mat a = apply_gains(b, {1.1, 0.9, 1.3});
  GainFitOptions o;
  o.max_texels = 1000;
  const cv::Mat w(64, 64, CV_32FC1, cv::Scalar(1));
  const GainFit f1 = fit_gains({{a, b, w}}, o), f2 = fit_gains({{a, b, w}}, o);
  EXPECT_LE(f1.texels_used, 1000);
  EXPECT_EQ(f1.gains, f2.gains);
  EXPECT_NEAR(f1.gains[0], 1 / 1.1, 1e-6);
}

TEST(GainFit, NoWeightIsAnError) {
  const cv::Mat b = reference_image(4);
  EXPECT_THROW(fit_gains({{b, b, cv::Mat(4, 4, CV_32FC1, cv::Scalar(0))}}, GainFitOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
