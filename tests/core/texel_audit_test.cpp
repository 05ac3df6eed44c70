#include "core/texel_audit.h"

#include "core/env_map.h"
#include "formats/exr_io.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace rsibr {
namespace {

cv::Scalar sums(const cv::Mat& m) { return cv::sum(m); }

// Ringing as a codec leaves it: a bright texel with a negative lobe beside it, on a dim field.
cv::Mat ringing_image(std::uint32_t seed) {
  cv::Mat m(32, 64, CV_32FC3, cv::Scalar(0.2, 0.3, 0.4));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int k = 0; k < 6; ++k) {
    const int r = 2 + int(rng() % 28), c = 2 + int(rng() % 60);
    const float peak = 100.f + 1e4f * u(rng);
    m.at<cv::Vec3f>(r, c) = cv::Vec3f(peak, 0.9f * peak, 0.8f * peak);
    m.at<cv::Vec3f>(r, c + 1) = cv::Vec3f(-0.1f * peak, -0.08f * peak, -0.05f * peak);
    m.at<cv::Vec3f>(r + 1, c) = cv::Vec3f(-0.02f * peak, 0.5f, -0.01f * peak);
  }
  return m;
}

TEST(RemoveNegativeRinging, KeepsEveryChannelsSumAndLeavesNoNegativeValue) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    cv::Mat m = ringing_image(seed);
    const cv::Scalar before = sums(m);
    const long negative = remove_negative_ringing(m);
    EXPECT_GT(negative, 0);
    const cv::Scalar after = sums(m);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(after[k], before[k], 1e-6 * std::abs(before[k])) << "seed " << seed;
    double lowest = 0;
    cv::minMaxLoc(m.reshape(1), &lowest);
    EXPECT_GE(lowest, 0.0);
  }
}

TEST(RemoveNegativeRinging, TakesTheDeficitFromTheNeighbourNotFromFarTexels) {
  cv::Mat m(16, 16, CV_32FC1, cv::Scalar(1.f));
  m.at<float>(8, 8) = 1000.f;
  m.at<float>(8, 9) = -100.f;
  remove_negative_ringing(m);
  EXPECT_FLOAT_EQ(m.at<float>(0, 0), 1.f);  // far away: untouched
  EXPECT_FLOAT_EQ(m.at<float>(15, 15), 1.f);
  EXPECT_NEAR(m.at<float>(8, 8), 900.f, 1.f);  // the bright source absorbed nearly all of it
  EXPECT_FLOAT_EQ(m.at<float>(8, 9), 0.f);
}

// Many deficits, some needing large windows, some at the borders (where the windows reflect).
cv::Mat crowded_ringing_image() {
  cv::Mat m(40, 50, CV_32FC3);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) {
      const float v = u(rng) < 0.3f ? -5.f * u(rng) : 10.f * u(rng) * u(rng);
      m.at<cv::Vec3f>(r, c) = cv::Vec3f(v, 0.5f * v, u(rng) < 0.5f ? 0.5f * v : v);
    }
  m(cv::Rect(10, 10, 12, 9)).setTo(cv::Scalar(-3, -1, -2));  // a hole only large windows fill
  return m;
}

TEST(RemoveNegativeRinging, SparseAndDenseStepsGiveTheSameValues) {
  for (cv::Mat base : {ringing_image(3), crowded_ringing_image()}) {
    cv::Mat sparse = base.clone(), dense = base.clone(), chosen = base.clone();
    const long n = remove_negative_ringing(sparse, FoldMethod::Sparse);
    EXPECT_EQ(remove_negative_ringing(dense, FoldMethod::Dense), n);
    EXPECT_EQ(remove_negative_ringing(chosen), n);
    double peak = 0;
    cv::minMaxLoc(cv::Mat(cv::abs(base)).reshape(1), nullptr, &peak);
    EXPECT_LE(cv::norm(sparse, dense, cv::NORM_INF), 1e-5 * peak);
    EXPECT_LE(cv::norm(chosen, dense, cv::NORM_INF), 1e-5 * peak);
    const cv::Scalar before = sums(base), after = sums(sparse);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(after[k], before[k], 1e-5 * std::abs(before[k]) + 1e-3);
  }
}

TEST(RemoveNegativeRinging, ZeroesWhatNoPositiveValueCanAbsorb) {
  cv::Mat m(4, 4, CV_32FC1, cv::Scalar(-1.f));
  EXPECT_EQ(remove_negative_ringing(m), 16);
  EXPECT_EQ(cv::countNonZero(m), 0);
}

TEST(RemoveNegativeRinging, LeavesAnImageWithoutNegativesBitIdentical) {
  cv::Mat m(8, 8, CV_32FC3, cv::Scalar(0.5, 2, 3));
  const cv::Mat copy = m.clone();
  EXPECT_EQ(remove_negative_ringing(m), 0);
  EXPECT_EQ(cv::norm(m, copy, cv::NORM_INF), 0.0);
}

TEST(SanitizeTexels, ZeroesNonFiniteAndHugeValuesAndFoldsNegatives) {
  cv::Mat m(4, 4, CV_32FC1, cv::Scalar(2.f));
  m.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  m.at<float>(1, 1) = std::numeric_limits<float>::infinity();
  m.at<float>(2, 2) = 3e38f;
  m.at<float>(3, 3) = -1.f;
  EXPECT_EQ(sanitize_texels(m), 4);
  const TexelAudit audit = audit_texels(m);
  EXPECT_FALSE(audit.bad());
  EXPECT_EQ(audit.negative, 0);
  EXPECT_NEAR(cv::sum(m)[0], 12 * 2.0 - 1.0, 1e-5);  // 12 plain texels of 2, the -1 taken from them
}

// The CC0 environments' ringing (lossy-compressed EXRs with a sun): folding keeps the integral
// within 1%, where zeroing the negatives added up to 14%.
TEST(RemoveNegativeRinging, KeepsTheIntegralOfRealEnvironmentsWithinOnePercent) {
  const auto envs = testing::real_environments();
  if (envs.empty()) GTEST_SKIP() << "the CC0 environments are not fetched (scripts/fetch-assets.sh)";
  int with_ringing = 0;
  for (const auto& file : envs) {
    EnvMap env = read_environment(file.string());
    const std::vector<double> before = integral(env);
    if (remove_negative_ringing(env.pixels) == 0) continue;
    ++with_ringing;
    const std::vector<double> after = integral(env);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(after[std::size_t(k)], before[std::size_t(k)], 0.01 * before[std::size_t(k)]) << file;
  }
  EXPECT_GT(with_ringing, 0) << "no fetched environment has negative values: the test checks nothing";
}

}  // namespace
}  // namespace rsibr
