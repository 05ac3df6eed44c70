// hdr/photo_set_merge.h with one exposure per view: no response can be recovered from one photo,
// so the sRGB curve is stated (its exact values at codes 0, 10, 188, 255), and the merge gives each
// pixel the sRGB-decoded code over the exposure, with the top code flagged clipped (a lower bound).
#include "formats/image_codecs.h"
#include "hdr/merge.h"
#include "hdr/photo_set_merge.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

// The curve written out again here, not taken from core/srgb_curve.h: the test must not share the
// code it checks.
double srgb(double u) { return u <= 0.04045 ? u / 12.92 : std::pow((u + 0.055) / 1.055, 2.4); }

TEST(OneExposure, TheSrgbResponseIsStatedAndTheTopCodeIsALowerBound) {
  const fs::path dir = fs::temp_directory_path() / ("rsibr-one-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // Codes 0..255 along x, the same in every channel and row.
  cv::Mat bgr(16, 256, CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(x), uchar(x), uchar(x));
  std::vector<PhotoView> views(2);
  for (int v = 0; v < 2; ++v) {
    const fs::path f = dir / ("v" + std::to_string(v) + ".png");
    ASSERT_TRUE(write_image(f.string(), bgr));
    views[std::size_t(v)].name = "v" + std::to_string(v);
    views[std::size_t(v)].brackets.push_back({f, 0.01 * (v + 1), 100.0, 1.0});
  }
  const PhotoSetResponse r = recover_photo_set_response({&views[0], &views[1]}, RecoveryOptions{}, Alignment::off);
  EXPECT_EQ(r.recovery.curve.model, "srgb");
  EXPECT_TRUE(r.from.empty());
  for (int z : {0, 10, 188, 255}) EXPECT_NEAR(r.recovery.curve.linear(1, z), srgb(z / 255.0), 1e-12) << z;

  const ViewMerge m = merge_photo_view(views[1], r.recovery.curve, r.noise, Alignment::off, MergeOptions{});
  const double e = 0.02;  // the view's relative exposure: t * iso / 100 / N^2
  for (int z : {10, 100, 188, 250}) {
    const cv::Vec3f p = m.image.radiance.at<cv::Vec3f>(8, z);
    EXPECT_NEAR(p[1], srgb(z / 255.0) / e, 1e-3 * srgb(z / 255.0) / e) << z;
    EXPECT_EQ(m.image.flags.at<unsigned char>(8, z) & kClipped, 0) << z;
  }
  EXPECT_NE(m.image.flags.at<unsigned char>(8, 255) & kClipped, 0);
  for (auto it = m.image.radiance.begin<cv::Vec3f>(); it != m.image.radiance.end<cv::Vec3f>(); ++it)
    ASSERT_TRUE(std::isfinite((*it)[0]) && std::isfinite((*it)[1]) && std::isfinite((*it)[2]));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rsibr
