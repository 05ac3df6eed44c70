// pipeline/default_sizes.h: map and probe sizes from the balls' pixel radii.
#include "pipeline/default_sizes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace rsibr {
namespace {

TEST(DefaultSizes, ACentredBallsPixelRadiusIsFTanAlpha) {
  const LensModel lens = LensModel::pinhole(2000, 4000, 3000);
  for (const double deg : {0.5, 3.0, 10.0}) {
    BallCone cone;
    cone.half_angle = deg * kPi / 180;
    EXPECT_NEAR(ball_pixel_radius(cone, lens), 2000 * std::tan(cone.half_angle), 1e-6 * 2000) << deg;
  }
}

TEST(DefaultSizes, AChromeMapHasATexelPerPixelAcrossTheBall) {
  EXPECT_EQ(default_map_size(BallKind::chrome, 459.3), 928);  // 2r = 918.6, up to a multiple of 16
  EXPECT_EQ(default_map_size(BallKind::chrome, 40), 80);
  EXPECT_EQ(default_map_size(BallKind::chrome, 5), 64);       // the smallest
  EXPECT_EQ(default_map_size(BallKind::chrome, 5000), 2048);  // the largest
  EXPECT_EQ(default_map_size(BallKind::grey, 459.3), 128);    // Lambert shading is smooth
  EXPECT_EQ(default_map_size(BallKind::glossy, 459.3), 256);
  EXPECT_EQ(default_map_size(BallKind::grey, 40), 80);
  EXPECT_EQ(default_map_size(BallKind::chrome, std::numeric_limits<double>::quiet_NaN()), 64);
  EXPECT_EQ(default_map_size(BallKind::chrome, -3), 64);
}

TEST(DefaultSizes, TheProbeIsAsSharpAsTheChromeMapsCentre) {
  // W = pi N / 2, a multiple of 64 in [256, 4096].
  EXPECT_EQ(default_probe_width(928), 1472);
  EXPECT_EQ(default_probe_width(64), 256);
  EXPECT_EQ(default_probe_width(2048), 3264);
  for (int n = 64; n <= 2048; n += 16) {
    const int w = default_probe_width(n);
    ASSERT_EQ(w % 64, 0);
    ASSERT_GE(w, std::min(4096.0, std::max(256.0, kPi * n / 2)));
  }
}

TEST(DefaultSizes, MemoryIsStatedPerTexel) {
  EXPECT_EQ(map_set_bytes(100, 3), 100u * 100u * 20u * 3u);
  EXPECT_EQ(probe_bytes(1472), 1472u * 736u * 36u);
}

}  // namespace
}  // namespace rsibr
