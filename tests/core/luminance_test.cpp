// The one luminance rule (core/luminance.h): the OCIO config's luma coefficients.
#include "core/luminance.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <cmath>
#include <limits>

namespace rsibr {
namespace {

TEST(Luminance, TheBuiltInConfigGivesRec709AndWhiteIsOne) {
  if (std::getenv("OCIO") && *std::getenv("OCIO")) GTEST_SKIP() << "$OCIO names another config";
  const auto& w = luma_coefficients();
  EXPECT_NEAR(w[0], 0.2126, 1e-4);
  EXPECT_NEAR(w[1], 0.7152, 1e-4);
  EXPECT_NEAR(w[2], 0.0722, 1e-4);
  EXPECT_NEAR(luminance(std::array<double, 3>{1, 1, 1}), 1.0, 1e-12);
  const float green[3] = {0, 2, 0};
  EXPECT_NEAR(luminance(green), 2 * w[1], 1e-12);
}

TEST(Luminance, PositiveLuminanceCountsNegativeAndNonFiniteChannelsAsZero) {
  const auto& w = luma_coefficients();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(positive_luminance(std::array<double, 3>{-1, nan, inf}), 0.0);
  EXPECT_NEAR(positive_luminance(std::array<double, 3>{-5, 1, 2}), w[1] + 2 * w[2], 1e-12);
  EXPECT_NEAR(luminance(std::array<double, 3>{-5, 1, 2}), -5 * w[0] + w[1] + 2 * w[2], 1e-12);
}

}  // namespace
}  // namespace rsibr
