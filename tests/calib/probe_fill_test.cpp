// calib/probe/probe_fill.h: the directions no view saw, filled from the seen ones.
#include "calib/probe/probe_fill.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace rsibr {
namespace {

constexpr int kW = 128, kH = 64;

// A lat-long map of L(direction), masks all zero.
struct Case {
  EnvMap env = EnvMap::zeros(Layout(LayoutKind::LatLong, kW, kH), 3);
  cv::Mat trusted = cv::Mat(kH, kW, CV_8UC1, cv::Scalar(1)), fill = cv::Mat(kH, kW, CV_8UC1, cv::Scalar(0));

  explicit Case(const std::function<Vec3(const Vec3&)>& radiance) {
    for (int r = 0; r < kH; ++r)
      for (int c = 0; c < kW; ++c) {
        const Vec3 l = radiance(*env.layout.texel_direction(c, r));
        env.pixels.at<cv::Vec3f>(r, c) = cv::Vec3f(float(l.x()), float(l.y()), float(l.z()));
      }
  }
  // Texels within `deg` of `axis` become unseen (0, to fill).
  void hole(const Vec3& axis, double deg) {
    for (int r = 0; r < kH; ++r)
      for (int c = 0; c < kW; ++c)
        if (env.layout.texel_direction(c, r)->dot(axis.normalized()) > std::cos(deg * kPi / 180)) {
          trusted.at<uchar>(r, c) = 0, fill.at<uchar>(r, c) = 1;
          env.pixels.at<cv::Vec3f>(r, c) = cv::Vec3f(0, 0, 0);
        }
  }
};

TEST(ProbeFill, TrustedTexelsAreLeftBitForBit) {
  Case k([](const Vec3& w) { return Vec3(1 + w.x(), 2 + w.y(), 3 + w.z()); });
  k.hole(Vec3(0, 0, 1), 30);
  const cv::Mat before = k.env.pixels.clone();
  const double f = fill_unseen(k.env, k.trusted, k.fill);
  EXPECT_GT(f, 0.05);
  EXPECT_LT(f, 0.08);  // a 30-degree cap is (1 - cos 30) / 2 = 6.7% of the sphere
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c)
      if (k.trusted.at<uchar>(r, c)) ASSERT_EQ(k.env.pixels.at<cv::Vec3f>(r, c), before.at<cv::Vec3f>(r, c));
}

TEST(ProbeFill, AConstantEnvironmentIsFilledWithItsConstant) {
  Case k([](const Vec3&) { return Vec3(0.2, 3, 40); });
  k.hole(Vec3(0, -1, 0), 40);  // the pole and the rows around it
  k.hole(Vec3(1, 0, 0), 20);
  fill_unseen(k.env, k.trusted, k.fill);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c) {
      const cv::Vec3f p = k.env.pixels.at<cv::Vec3f>(r, c);
      ASSERT_NEAR(p[0], 0.2, 1e-5);
      ASSERT_NEAR(p[1], 3, 1e-4);
      ASSERT_NEAR(p[2], 40, 1e-3);
    }
}

TEST(ProbeFill, ASmoothFieldIsInterpolatedAcrossASmallHole) {
  Case k([](const Vec3& w) { return Vec3::Constant(std::exp(1.5 * w.y() + 0.5 * w.x())); });
  const Case truth = k;
  k.hole(Vec3(0.3, 0.2, 1), 12);
  fill_unseen(k.env, k.trusted, k.fill);
  double worst = 0;
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c)
      if (k.fill.at<uchar>(r, c))
        worst = std::max(worst, std::abs(std::log(double(k.env.pixels.at<cv::Vec3f>(r, c)[0]) /
                                                  truth.env.pixels.at<cv::Vec3f>(r, c)[0])));
  EXPECT_LT(worst, 0.15);  // stops: e^0.15 = 16% at worst, at the centre of a 24-degree hole
}

TEST(ProbeFill, AHoleAcrossTheSeamHasNoSeam) {
  // The seam is at azimuth 180 degrees (-Z here): columns 0 and W - 1 are that direction.
  Case k([](const Vec3& w) { return Vec3::Constant(std::exp(w.x() + 0.5 * w.y())); });
  const Case truth = k;
  const Vec3 seam = *k.env.layout.texel_direction(0, kH / 2);
  k.hole(seam, 25);
  ASSERT_TRUE(k.fill.at<uchar>(kH / 2, 0) && k.fill.at<uchar>(kH / 2, kW - 1));
  fill_unseen(k.env, k.trusted, k.fill);
  for (int r = 0; r < kH; ++r) {
    if (!k.fill.at<uchar>(r, 0)) continue;
    const float a = k.env.pixels.at<cv::Vec3f>(r, 0)[0], b = k.env.pixels.at<cv::Vec3f>(r, kW - 1)[0];
    ASSERT_EQ(a, b) << r;  // one direction, one value
    // Across the seam (columns 1 and W - 2, two texels apart) the step is the field's own.
    const double a1 = k.env.pixels.at<cv::Vec3f>(r, 1)[0], b1 = k.env.pixels.at<cv::Vec3f>(r, kW - 2)[0];
    const double t1 = truth.env.pixels.at<cv::Vec3f>(r, 1)[0], u1 = truth.env.pixels.at<cv::Vec3f>(r, kW - 2)[0];
    EXPECT_NEAR(std::log(a1 / b1), std::log(t1 / u1), 0.03) << r;
  }
}

TEST(ProbeFill, ASunBesideAHoleDoesNotSpreadOverIt) {
  const Vec3 sun = Vec3(0.5, 0.3, 0.8).normalized();
  Case k([&](const Vec3& w) { return Vec3::Constant(w.dot(sun) > std::cos(3 * kPi / 180) ? 1e9 : 1.0); });
  k.hole(Vec3(0.5, 0.3, 0.8).normalized() + Vec3(0.3, 0, -0.2), 20);
  ASSERT_GT(cv::countNonZero(k.fill), 10);
  fill_unseen(k.env, k.trusted, k.fill);
  float brightest = 0;
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c)
      if (k.fill.at<uchar>(r, c)) brightest = std::max(brightest, k.env.pixels.at<cv::Vec3f>(r, c)[1]);
  EXPECT_LT(brightest, 1e3);  // an arithmetic mean beside the sun would be ~1e7
}

TEST(ProbeFill, PoleTexelsAreOneValue) {
  Case k([](const Vec3& w) { return Vec3::Constant(1 + w.x() * w.x()); });
  k.hole(Vec3(0, 1, 0), 15);
  fill_unseen(k.env, k.trusted, k.fill);
  for (int c = 1; c < kW; ++c) ASSERT_EQ(k.env.pixels.at<cv::Vec3f>(0, c), k.env.pixels.at<cv::Vec3f>(0, 0));
}

TEST(ProbeFill, ZeroAndNegativeTexelsDoNotMakeNaN) {
  Case k([](const Vec3& w) { return Vec3(w.x() > 0 ? 0.0 : 1.0, -1.0, 1e-30); });
  k.hole(Vec3(0, 0, 1), 30);
  fill_unseen(k.env, k.trusted, k.fill);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c)
      for (int ch = 0; ch < 3; ++ch) {
        const float v = k.env.pixels.at<cv::Vec3f>(r, c)[ch];
        ASSERT_TRUE(std::isfinite(v)) << r << " " << c;
        if (k.fill.at<uchar>(r, c)) ASSERT_GE(v, 0.0f);
      }
}

TEST(ProbeFill, NothingToFillChangesNothingAndNothingTrustedIsAnError) {
  Case k([](const Vec3& w) { return Vec3::Constant(2 + w.z()); });
  const cv::Mat before = k.env.pixels.clone();
  EXPECT_EQ(fill_unseen(k.env, k.trusted, k.fill), 0.0);
  EXPECT_EQ(cv::norm(k.env.pixels, before, cv::NORM_INF), 0.0);
  k.trusted.setTo(0);
  k.fill.setTo(1);
  EXPECT_THROW(fill_unseen(k.env, k.trusted, k.fill), std::invalid_argument);
  EXPECT_THROW(fill_unseen(k.env, cv::Mat(3, 3, CV_8UC1, cv::Scalar(1)), k.fill), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
