// capture/camera_response.h: every response is an increasing bijection of [0,1] with its inverse.
#include "capture/camera_response.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

TEST(CameraResponse, EveryKindIsIncreasingAndFixesTheEnds) {
  for (const std::string& kind : CameraResponse::kinds()) {
    const CameraResponse r(kind);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(r.code(0, c), 0, 1e-15) << kind;
      EXPECT_NEAR(r.code(1, c), 1, 1e-12) << kind;
      double prev = -1;
      for (int i = 0; i <= 1000; ++i) {
        const double f = r.code(i / 1000.0, c);
        EXPECT_GT(f, prev) << kind << " at " << i;
        prev = f;
      }
    }
  }
}

TEST(CameraResponse, InverseUndoesTheCurve) {
  for (const std::string& kind : CameraResponse::kinds()) {
    const CameraResponse r(kind);
    for (int c = 0; c < 3; ++c)
      for (double x : {0.0, 1e-6, 0.001, 0.0031308, 0.01, 0.18, 0.5, 0.9, 1.0})
        EXPECT_NEAR(r.relative(r.code(x, c), c), x, 1e-12 * (1 + x)) << kind;
  }
}

TEST(CameraResponse, SrgbMatchesTheStandardAtKnownPoints) {
  const CameraResponse r("srgb");
  EXPECT_NEAR(r.code(0.18, 0), 0.46135612950044164, 1e-12);  // 18% grey -> 118 of 255
  EXPECT_NEAR(r.code(0.002, 1), 12.92 * 0.002, 1e-15);
}

TEST(CameraResponse, MeasuredCurveDiffersPerChannel) {
  const CameraResponse r("measured");
  EXPECT_GT(std::abs(r.code(0.1, 0) - r.code(0.1, 1)), 0.005);
  EXPECT_GT(std::abs(r.code(0.1, 2) - r.code(0.1, 1)), 0.005);
}

TEST(CameraResponse, TableListsEveryCodeWithItsRelativeExposure) {
  const CameraResponse r("measured");
  const auto t = r.table(255);
  ASSERT_EQ(t.size(), 256u);
  EXPECT_EQ(t[0][1], 0);
  EXPECT_NEAR(t[255][2], 1, 1e-12);
  EXPECT_NEAR(r.code(t[100][3], 2) * 255, 100, 1e-9);
  EXPECT_THROW(CameraResponse("gamma"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
