// Colour of merged images (hdr/merged_colour.h): the camera space to the working space and a
// white balance, on the radiance and its variance alike.
#include "hdr/merged_colour.h"

#include "core/colour.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace rsibr {
namespace {

MergedImage random_merged(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.01f, 4.0f);
  MergedImage m;
  m.radiance = cv::Mat(5, 7, CV_32FC3);
  m.variance = cv::Mat(5, 7, CV_32FC3);
  m.flags = cv::Mat(5, 7, CV_8UC1, cv::Scalar(3));
  for (int r = 0; r < 5; ++r)
    for (int x = 0; x < 7; ++x) {
      m.radiance.at<cv::Vec3f>(r, x) = {u(rng), u(rng), u(rng)};
      m.variance.at<cv::Vec3f>(r, x) = {u(rng) * 1e-3f, u(rng) * 1e-3f, u(rng) * 1e-3f};
    }
  return m;
}

TEST(MergedColour, TheRadianceGoesThroughOCIOAndTheVarianceThroughTheSquaredMatrix) {
  const std::string working = working_space();
  const MergedImage before = random_merged(1);
  MergedImage m = random_merged(1);
  merged_to_working_space(m, "lin_p3d65");
  cv::Mat expected = before.radiance.clone();
  convert_colour_space(expected, "lin_p3d65", working);
  EXPECT_LT(cv::norm(m.radiance, expected, cv::NORM_INF), 1e-5);
  const cv::Matx33f M = colour_conversion_matrix("lin_p3d65", working);
  for (int r = 0; r < 5; ++r)
    for (int x = 0; x < 7; ++x) {
      const cv::Vec3f v = before.variance.at<cv::Vec3f>(r, x);
      for (int i = 0; i < 3; ++i) {
        const double want = M(i, 0) * M(i, 0) * v[0] + M(i, 1) * M(i, 1) * v[1] + M(i, 2) * M(i, 2) * v[2];
        EXPECT_NEAR(m.variance.at<cv::Vec3f>(r, x)[i], want, 1e-6 * (1 + want));
      }
    }
  EXPECT_EQ(cv::norm(m.flags, before.flags, cv::NORM_INF), 0);
  // P3's red is outside Rec.709: its matrix mixes the channels (not a diagonal).
  EXPECT_GT(M(0, 0), 1.0f);
  EXPECT_LT(M(1, 0), 0.0f);
}

TEST(MergedColour, TheWorkingSpaceAndNoSpaceAreNoOps) {
  const MergedImage before = random_merged(2);
  for (const std::string& from : {std::string(), working_space()}) {
    MergedImage m = random_merged(2);
    merged_to_working_space(m, from);
    EXPECT_EQ(cv::norm(m.radiance, before.radiance, cv::NORM_INF), 0) << from;
    EXPECT_EQ(cv::norm(m.variance, before.variance, cv::NORM_INF), 0) << from;
  }
  const cv::Matx33f I = colour_conversion_matrix(working_space(), working_space());
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(I(i, j), i == j ? 1 : 0, 1e-6);
}

TEST(MergedColour, AWhiteBalanceScalesTheVarianceBySquaredGains) {
  const MergedImage before = random_merged(3);
  MergedImage m = random_merged(3);
  apply_white_balance(m, {2.0f, 1.0f, 0.5f});
  const cv::Vec3f r0 = before.radiance.at<cv::Vec3f>(2, 3), v0 = before.variance.at<cv::Vec3f>(2, 3);
  EXPECT_FLOAT_EQ(m.radiance.at<cv::Vec3f>(2, 3)[0], 2 * r0[0]);
  EXPECT_FLOAT_EQ(m.radiance.at<cv::Vec3f>(2, 3)[2], 0.5f * r0[2]);
  EXPECT_FLOAT_EQ(m.variance.at<cv::Vec3f>(2, 3)[0], 4 * v0[0]);
  EXPECT_FLOAT_EQ(m.variance.at<cv::Vec3f>(2, 3)[1], v0[1]);
  EXPECT_FLOAT_EQ(m.variance.at<cv::Vec3f>(2, 3)[2], 0.25f * v0[2]);
}

TEST(MergedColour, RawIsRec709UnlessTheUserSaysAndDisplaySpacesAreRefused) {
  EXPECT_EQ(merged_colour_space("", true), "lin_rec709");
  EXPECT_EQ(merged_colour_space("", false), "");
  EXPECT_EQ(merged_colour_space("ACEScg", true), "ACEScg");
  // An encoded (display) space is not a linear camera space: refused, not silently bent.
  try {
    colour_conversion_matrix("srgb_texture", working_space());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a linear conversion"), std::string::npos) << e.what();
  }
  EXPECT_THROW(colour_conversion_matrix("no such space", working_space()), std::runtime_error);
}

}  // namespace
}  // namespace rsibr
