// Cell-centred lat-long images (Blender's convention): directions and the resampling.
#include "core/cell_centred_latlong.h"

#include <OpenEXR/ImfEnvmap.h>
#include <gtest/gtest.h>

namespace rsibr {
namespace {

// rsibr's continuous pixel of the cell-centred texel (i, j): ((i+0.5)(W-1)/W, (j+0.5)(H-1)/H).
Vec3 rsibr_direction_of_cell(int i, int j, int w, int h) {
  const Layout L(LayoutKind::LatLong, w, h);
  return *L.direction(Vec2((i + 0.5) * (w - 1) / w, (j + 0.5) * (h - 1) / h));
}

TEST(CellCentredLatLong, TexelCentresAreRsibrPixelsHalfATexelIn) {
  for (const auto& [w, h] : {std::pair{16, 8}, std::pair{7, 3}, std::pair{512, 256}})
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        const Vec3 d = cell_centred_latlong_direction(i, j, w, h);
        EXPECT_NEAR((d - rsibr_direction_of_cell(i, j, w, h)).norm(), 0, 1e-6) << i << "," << j;
      }
}

TEST(CellCentredLatLong, AxesMatchBlenderEquirectangular) {
  // Blender's Environment Texture: u = 0.5 - atan2(dy, dx) / 2pi, v = 0.5 + asin(dz) / pi (v up) in
  // its +Z-up world, whose (x, y, z) is rsibr's (z, x, y). Image row j (top first) has v = 1 - (j+0.5)/H.
  const int w = 64, h = 32;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const Vec3 d = cell_centred_latlong_direction(i, j, w, h);
      const Vec3 blender(d.z(), d.x(), d.y());
      double u = 0.5 - std::atan2(blender.y(), blender.x()) / (2 * kPi);
      const double v = 0.5 + std::asin(std::clamp(blender.z(), -1.0, 1.0)) / kPi;
      u -= std::floor(u);
      EXPECT_NEAR(std::fmod(u * w - (i + 0.5) + w, double(w)), 0, 1e-6);
      EXPECT_NEAR((1 - v) * h - (j + 0.5), 0, 1e-6);
    }
}

TEST(CellCentredLatLong, ResamplingInterpolatesRsibrTexelsLinearly) {
  // Values linear in rsibr's column and row are reproduced exactly by the bilinear resampling.
  const int w = 32, h = 16;
  EnvMap env = EnvMap::zeros(Layout(LayoutKind::LatLong, w, h), 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) env.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(float(x), float(y), 1.0f);
  const EnvMap out = to_cell_centred_latlong(env, w, h);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const cv::Vec3f v = out.pixels.at<cv::Vec3f>(j, i);
      EXPECT_NEAR(v[0], (i + 0.5) * (w - 1) / w, 2e-4) << i << "," << j;
      EXPECT_NEAR(v[1], (j + 0.5) * (h - 1) / h, 2e-4) << i << "," << j;
      EXPECT_FLOAT_EQ(v[2], 1.0f);
    }
}

TEST(CellCentredLatLong, ConstantEnvironmentStaysConstantAndKeepsAttributes) {
  EnvMap env = EnvMap::zeros(Layout::with_size(LayoutKind::Cube, 8), 4);
  env.pixels.setTo(cv::Scalar(2, 3, 4, 1));
  env.attributes["source"] = "test";
  const EnvMap out = to_cell_centred_latlong(env, 20, 10);
  EXPECT_EQ(out.layout.kind(), LayoutKind::LatLong);
  EXPECT_EQ(out.pixels.cols, 20);
  EXPECT_EQ(out.pixels.rows, 10);
  EXPECT_EQ(out.attributes.at("source"), "test");
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 20; ++i)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(out.pixels.at<cv::Vec4f>(j, i)[c], c == 3 ? 1 : c + 2, 1e-5);
}

}  // namespace
}  // namespace rsibr
