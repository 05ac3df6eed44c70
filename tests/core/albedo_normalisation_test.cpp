// Albedo-normalised maps: the table lookup's exact values, and normalise/denormalise as inverses.
#include "core/albedo_normalisation.h"

#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

// Rows at cos_k = (k + 0.5) / 4: r = cos_k, g = 1 - cos_k, b = 0.5.
std::vector<float> ramp_table() {
  std::vector<float> t;
  for (int k = 0; k < 4; ++k) {
    const float c = (float(k) + 0.5f) / 4.0f;
    t.insert(t.end(), {c, 1.0f - c, 0.5f});
  }
  return t;
}

TEST(AlbedoTable, ExactAtRowsLinearBetweenAndClampedOutside) {
  const std::vector<float> t = ramp_table();
  for (int k = 0; k < 4; ++k) {
    const float c = (float(k) + 0.5f) / 4.0f;
    EXPECT_FLOAT_EQ(float(albedo_at(t, c).x()), c);
    EXPECT_FLOAT_EQ(float(albedo_at(t, c).y()), 1.0f - c);
  }
  // A linear function is reproduced between rows.
  for (float c = 0.125f; c <= 0.875f; c += 0.01f) EXPECT_NEAR(albedo_at(t, c).x(), c, 1e-6);
  // Outside: the end rows.
  EXPECT_FLOAT_EQ(float(albedo_at(t, 0.0f).x()), 0.125f);
  EXPECT_FLOAT_EQ(float(albedo_at(t, -3.0f).x()), 0.125f);
  EXPECT_FLOAT_EQ(float(albedo_at(t, 1.0f).x()), 0.875f);
  EXPECT_FLOAT_EQ(float(albedo_at(t, 7.0f).x()), 0.875f);
  EXPECT_FLOAT_EQ(float(albedo_at(t, 0.3f).z()), 0.5f);
}

TEST(AlbedoTable, BadTablesAreRejected) {
  EXPECT_THROW(check_albedo_table({}), std::invalid_argument);
  EXPECT_THROW(check_albedo_table({1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(check_albedo_table({1, 1, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(check_albedo_table({1, 1, 1, 1, NAN, 1}), std::invalid_argument);
  EXPECT_THROW(check_albedo_table({1, 1, 1, 1, -0.5f, 1}), std::invalid_argument);
  EXPECT_NO_THROW(check_albedo_table({0, 0, 0, 1, 1, 1}));
}

TEST(AlbedoNormalisation, DenormaliseUndoesNormaliseInsideTheDiscAndLeavesTheOutside) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1e4f);
  cv::Mat map(31, 31, CV_32FC3);
  for (float *p = map.ptr<float>(), *e = p + 31 * 31 * 3; p != e; ++p) *p = u(rng);
  cv::Mat m = map.clone();
  const std::vector<float> t = ramp_table();
  normalise_by_albedo(m, t);
  denormalise_by_albedo(m, t);
  for (int r = 0; r < 31; ++r)
    for (int c = 0; c < 31; ++c)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.at<cv::Vec3f>(r, c)[k], map.at<cv::Vec3f>(r, c)[k], 2e-7 * 1e4);
  // Outside the disc (the corners) nothing changes, bit for bit.
  EXPECT_EQ(m.at<cv::Vec3f>(0, 0), map.at<cv::Vec3f>(0, 0));
}

TEST(AlbedoNormalisation, ZeroAlbedoStoresZeroNeverNaN) {
  cv::Mat m(16, 16, CV_32FC3, cv::Scalar(1e30f, 0.0f, 5.0f));
  normalise_by_albedo(m, {0, 0, 0, 0, 0, 0});
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 16; ++c)
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(m.at<cv::Vec3f>(r, c)[k]));
  EXPECT_EQ(m.at<cv::Vec3f>(8, 8), cv::Vec3f(0, 0, 0));
  // A tiny but non-zero albedo with a huge radiance: finite or +inf? Stored values must stay finite.
  cv::Mat s(16, 16, CV_32FC3, cv::Scalar(1e30f, 1e30f, 1e30f));
  normalise_by_albedo(s, {1e-11f, 1e-11f, 1e-11f, 1e-11f, 1e-11f, 1e-11f});
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 16; ++c)
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(s.at<cv::Vec3f>(r, c)[k]));
}

}  // namespace
}  // namespace rsibr
