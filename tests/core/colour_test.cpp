#include "core/colour.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

namespace fs = std::filesystem;

// Every test starts and ends with $OCIO unset and no cached config, so the embedded one is used.
class Colour : public ::testing::Test {
 protected:
  void SetUp() override {
    unsetenv("OCIO");
    rsibr::reset_colour_config_for_testing();
  }
  void TearDown() override {
    unsetenv("OCIO");
    rsibr::reset_colour_config_for_testing();
  }
};

cv::Mat pixel(float r, float g, float b) { return cv::Mat(1, 1, CV_32FC3, cv::Scalar(r, g, b)); }

cv::Vec3f converted(cv::Vec3f rgb, const std::string& from, const std::string& to) {
  cv::Mat m = pixel(rgb[0], rgb[1], rgb[2]);
  rsibr::convert_colour_space(m, from, to);
  return m.at<cv::Vec3f>(0, 0);
}

void expect_near(cv::Vec3f a, cv::Vec3f b, float tol) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << "channel " << c;
}

// The display code for one channel value, read back in RGB order from the BGR result.
cv::Vec3b encoded(float r, float g, float b, float stops = 0.0f) {
  const cv::Mat out = rsibr::display_encode(pixel(r, g, b), stops);
  EXPECT_EQ(out.type(), CV_8UC3);
  const cv::Vec3b bgr = out.at<cv::Vec3b>(0, 0);
  return {bgr[2], bgr[1], bgr[0]};
}

TEST_F(Colour, EmbeddedConfigIsValid) {
  const auto config = rsibr::colour_config();
  ASSERT_TRUE(config);
  EXPECT_NO_THROW(config->validate());
  EXPECT_EQ(config->getMajorVersion(), 2u);
  for (const char* name : {"lin_rec709", "ACEScg", "ACES2065-1", "lin_p3d65", "srgb_texture", "raw"}) {
    EXPECT_TRUE(config->getColorSpace(name)) << name;
  }
  EXPECT_STREQ(config->getDefaultDisplay(), "sRGB");
  EXPECT_STREQ(config->getDefaultView("sRGB"), "Standard");
  EXPECT_TRUE(config->getColorSpace("raw")->isData());
}

TEST_F(Colour, ConfigIsCached) { EXPECT_EQ(rsibr::colour_config().get(), rsibr::colour_config().get()); }

TEST_F(Colour, WorkingSpaceIsLinearRec709) {
  EXPECT_EQ(rsibr::working_space(), "lin_rec709");
  const auto config = rsibr::colour_config();
  EXPECT_STREQ(config->getColorSpace("reference")->getName(), "lin_rec709");
  EXPECT_FALSE(config->getColorSpace("lin_rec709")->isData());
}

TEST_F(Colour, AcesCgRoundTripIsIdentity) {
  cv::Mat img(4, 5, CV_32FC3);
  cv::randu(img, cv::Scalar::all(-0.5), cv::Scalar::all(20.0));
  const cv::Mat original = img.clone();
  rsibr::convert_colour_space(img, "lin_rec709", "ACEScg");
  EXPECT_GT(cv::norm(img, original, cv::NORM_INF), 1e-2);  // it did change something
  rsibr::convert_colour_space(img, "ACEScg", "lin_rec709");
  EXPECT_LE(cv::norm(img, original, cv::NORM_INF), 1e-5 * 20.0);
  EXPECT_LE(cv::norm(img, original, cv::NORM_RELATIVE | cv::NORM_INF), 1e-5);
}

TEST_F(Colour, WhiteStaysWhiteThroughAcesCg) {
  const cv::Vec3f white(1.0f, 1.0f, 1.0f);
  expect_near(converted(white, "lin_rec709", "ACEScg"), white, 1e-5f);
  expect_near(converted(converted(white, "lin_rec709", "ACEScg"), "ACEScg", "lin_rec709"), white, 1e-5f);
  expect_near(converted(white, "lin_rec709", "ACES2065-1"), white, 1e-5f);
  expect_near(converted(white, "lin_rec709", "lin_p3d65"), white, 1e-5f);
  // Published Bradford-adapted sRGB -> ACEScg matrix, first column.
  expect_near(converted({1.0f, 0.0f, 0.0f}, "lin_rec709", "ACEScg"), {0.6131f, 0.0702f, 0.0206f}, 1e-3f);
  // ACES AP0 -> AP1 (published ACES matrix, independent of D65) via the two config spaces.
  expect_near(converted({1.0f, 0.0f, 0.0f}, "ACES2065-1", "ACEScg"), {1.4514393161f, -0.0765537734f, 0.0083161484f},
              1e-4f);
}

TEST_F(Colour, SrgbTextureDecodesWithTheSrgbCurve) {
  // 0.5 encoded -> ((0.5 + 0.055) / 1.055)^2.4 = 0.21404; 0.02 encoded is on the linear toe.
  expect_near(converted({0.5f, 1.0f, 0.0f}, "srgb_texture", "lin_rec709"), {0.21404f, 1.0f, 0.0f}, 1e-5f);
  EXPECT_NEAR(converted({0.02f, 0.02f, 0.02f}, "srgb_texture", "lin_rec709")[0], 0.02f / 12.92f, 2e-5f);
}

TEST_F(Colour, AlphaIsUntouched) {
  cv::Mat rgba(2, 2, CV_32FC4, cv::Scalar(1.0f, 0.0f, 0.0f, 0.25f));
  rsibr::convert_colour_space(rgba, "lin_rec709", "ACEScg");
  const cv::Vec4f p = rgba.at<cv::Vec4f>(1, 1);
  EXPECT_NEAR(p[0], 0.6131f, 1e-3f);
  EXPECT_EQ(p[3], 0.25f);
}

TEST_F(Colour, ConversionWorksOnRegionsOfInterest) {
  cv::Mat big(4, 4, CV_32FC3, cv::Scalar(1.0f, 0.0f, 0.0f));
  cv::Mat roi = big(cv::Rect(1, 1, 2, 2));
  rsibr::convert_colour_space(roi, "lin_rec709", "ACEScg");
  EXPECT_NEAR(big.at<cv::Vec3f>(1, 2)[0], 0.6131f, 1e-3f);
  EXPECT_EQ(big.at<cv::Vec3f>(0, 0)[0], 1.0f);  // outside the region
  EXPECT_EQ(big.at<cv::Vec3f>(3, 3)[0], 1.0f);
}

TEST_F(Colour, ChromaticitiesOfRec709GiveIdentity) {
  const Eigen::Matrix3d m = rsibr::working_from_chromaticities(Imf::Chromaticities());
  EXPECT_LE((m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-6) << m;
}

TEST_F(Colour, ChromaticitiesOfAcesAp0MatchConfigMatrix) {
  const Imf::Chromaticities ap0({0.7347f, 0.2653f}, {0.0f, 1.0f}, {0.0001f, -0.0770f}, {0.32168f, 0.33767f});
  const Eigen::Matrix3d m = rsibr::working_from_chromaticities(ap0);
  for (int col = 0; col < 3; ++col) {
    cv::Vec3f unit(0.0f, 0.0f, 0.0f);
    unit[col] = 1.0f;
    const cv::Vec3f ocio = converted(unit, "ACES2065-1", "lin_rec709");
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(m(row, col), ocio[row], 1e-4) << "row " << row << " col " << col;
    }
  }
  EXPECT_LE((m * Eigen::Vector3d::Ones() - Eigen::Vector3d::Ones()).cwiseAbs().maxCoeff(), 1e-5);
}

TEST_F(Colour, ChromaticitiesOfP3D65NeedNoAdaptation) {
  const Imf::Chromaticities p3({0.680f, 0.320f}, {0.265f, 0.690f}, {0.150f, 0.060f}, {0.3127f, 0.3290f});
  const Eigen::Matrix3d m = rsibr::working_from_chromaticities(p3);
  const cv::Vec3f g = converted({0.0f, 1.0f, 0.0f}, "lin_p3d65", "lin_rec709");
  for (int row = 0; row < 3; ++row) EXPECT_NEAR(m(row, 1), g[row], 1e-4);
}

TEST_F(Colour, OcioEnvironmentVariableIsHonoured) {
  const fs::path path = fs::temp_directory_path() / ("rsibr_colour_test_" + std::to_string(::getpid()) + ".ocio");
  {
    std::ofstream out(path);
    out << R"(ocio_profile_version: 2
roles:
  default: linear_other
  scene_linear: linear_other
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  other:
    - !<View> {name: Plain, colorspace: linear_other}
colorspaces:
  - !<ColorSpace>
    name: linear_other
    isdata: false
)";
  }
  EXPECT_EQ(rsibr::working_space(), "lin_rec709");  // cached embedded config
  setenv("OCIO", path.c_str(), 1);
  EXPECT_EQ(rsibr::working_space(), "lin_rec709");  // still cached until reset
  rsibr::reset_colour_config_for_testing();
  EXPECT_EQ(rsibr::working_space(), "linear_other");
  EXPECT_STREQ(rsibr::colour_config()->getDefaultDisplay(), "other");

  setenv("OCIO", "", 1);  // empty means unset
  rsibr::reset_colour_config_for_testing();
  EXPECT_EQ(rsibr::working_space(), "lin_rec709");
  fs::remove(path);
}

TEST_F(Colour, MissingOcioFileIsAClearError) {
  const std::string path = "/nonexistent/rsibr/config.ocio";
  setenv("OCIO", path.c_str(), 1);
  try {
    rsibr::colour_config();
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("$OCIO"), std::string::npos) << what;
  }
}

TEST_F(Colour, UnknownColourSpaceIsAClearError) {
  cv::Mat img = pixel(0.5f, 0.5f, 0.5f);
  try {
    rsibr::convert_colour_space(img, "lin_rec709", "no_such_space");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'no_such_space'"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(rsibr::convert_colour_space(img, "bogus", "ACEScg"), std::runtime_error);
  EXPECT_EQ(img.at<cv::Vec3f>(0, 0)[0], 0.5f);  // untouched
  EXPECT_THROW(rsibr::display_encode(img, 0.0f, "NoSuchDisplay"), std::runtime_error);
  EXPECT_THROW(rsibr::display_encode(img, 0.0f, "sRGB", "NoSuchView"), std::runtime_error);
}

TEST_F(Colour, DisplayEncodeMatchesSrgbCurve) {
  // sRGB encoding of 0.18 = 1.055 * 0.18^(1/2.4) - 0.055 = 0.4614 -> 117.7 -> 118.
  EXPECT_EQ(encoded(0.18f, 1.0f, 0.0f), cv::Vec3b(118, 255, 0));
  // Channel order: a red pixel is BGR (0, 0, 255) in the returned image.
  const cv::Mat red = rsibr::display_encode(pixel(1.0f, 0.0f, 0.0f), 0.0f);
  EXPECT_EQ(red.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));
  // Exposure: +1 stop on 0.09 is 0.18.
  EXPECT_EQ(encoded(0.09f, 0.09f, 0.09f, 1.0f), cv::Vec3b(118, 118, 118));
  // Linear toe: 0.002 * 12.92 * 255 = 6.6 -> 7.
  EXPECT_EQ(encoded(0.002f, 0.002f, 0.002f)[0], 7);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(encoded(nan, 0.18f, nan), cv::Vec3b(0, 118, 0));
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(encoded(inf, -inf, -1.0f), cv::Vec3b(255, 0, 0));
}

TEST_F(Colour, HugeValuesDoNotOverflowDisplayEncode) {
  EXPECT_EQ(encoded(1e9f, 1e9f, 1e9f), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(encoded(std::numeric_limits<float>::max(), 1e30f, 2.0f), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(encoded(1.0f, 1.0f, 1.0f, 200.0f), cv::Vec3b(255, 255, 255));  // gain overflows to inf
  EXPECT_EQ(encoded(-1e9f, -1e30f, 0.0f), cv::Vec3b(0, 0, 0));
}

TEST_F(Colour, DisplayEncodeKeepsSizeAndAcceptsAlpha) {
  const cv::Mat rgba(3, 7, CV_32FC4, cv::Scalar(0.18f, 0.18f, 0.18f, 0.0f));
  const cv::Mat out = rsibr::display_encode(rgba, 0.0f);
  ASSERT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(out.size(), cv::Size(7, 3));
  EXPECT_EQ(out.at<cv::Vec3b>(2, 6), cv::Vec3b(118, 118, 118));
  EXPECT_TRUE(rsibr::display_encode(cv::Mat(0, 0, CV_32FC3), 0.0f).empty());
}

}  // namespace
