// capture/camera_processing.h: in-camera processing in the order cameras apply it, greys kept grey,
// what a merge can recover, and a JPEG stage that behaves like a camera's (saturated signal below
// the top code).
#include "capture/camera_processing.h"

#include "capture/synth_capture.h"
#include "core/test_data.h"
#include "formats/truth_image.h"
#include "synth_cases.h"
#include "formats/image_codecs.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>

namespace rsibr {
namespace {

CameraProcessing consumer() {
  CameraProcessing p;
  p.sensitivity = Vec3(0.55, 1.0, 0.72);
  p.saturation = 1.3;
  return p;
}

TEST(CameraProcessing, TheColourMatrixKeepsGreysAndLuminanceAndBoostsColour) {
  const Mat3 M = consumer().matrix();
  const Vec3 y(0.2126, 0.7152, 0.0722);
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(M.row(r).sum(), 1.0, 1e-12);
  const Vec3 colour(0.6, 0.3, 0.1);
  const Vec3 out = M * colour;
  EXPECT_NEAR(y.dot(out), y.dot(colour), 1e-12);
  EXPECT_GT(out[0] - out[2], colour[0] - colour[2]);  // further from grey
  EXPECT_TRUE(consumer().gains().isApprox(Vec3(1 / 0.55, 1, 1 / 0.72)));
}

TEST(CameraProcessing, ANeutralRadianceRecordsEqualCodesInEveryChannel) {
  const CameraProcessing p = consumer();
  const CameraResponse filmic("filmic");
  // Neutral light: the raw channels differ by the sensitivities, the white balance undoes it.
  cv::Mat raw(1, 40, CV_64FC3);
  for (int x = 0; x < raw.cols; ++x) {
    const double v = 0.9 * (x + 1) / raw.cols;
    raw.at<cv::Vec3d>(0, x) = cv::Vec3d(v * 0.55, v, v * 0.72);
  }
  const cv::Mat codes = process_raw(raw, p, filmic, 255);
  for (int x = 0; x < raw.cols; ++x) {
    const auto z = codes.at<cv::Vec3w>(0, x);
    EXPECT_EQ(z[0], z[1]) << x;
    EXPECT_EQ(z[2], z[1]) << x;
  }
}

TEST(CameraProcessing, WhiteBalanceClipsBeforeTheMatrixAndTheToneCurveComesLast) {
  // Raw red at 0.7 with gain 1/0.55: white-balanced 1.27, clipped to 1 before the matrix mixes it,
  // so green and blue see a red of 1, not 1.27; the tone curve maps the matrix output.
  const CameraProcessing p = consumer();
  const CameraResponse filmic("filmic");
  cv::Mat raw(1, 1, CV_64FC3);
  raw.at<cv::Vec3d>(0, 0) = cv::Vec3d(0.7, 0.4, 0.2);
  const auto z = process_raw(raw, p, filmic, 255).at<cv::Vec3w>(0, 0);
  const Vec3 w(std::min(1.0, 0.7 / 0.55), 0.4, std::min(1.0, 0.2 / 0.72));
  const Vec3 m = p.matrix() * w;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(z[c], std::lround(filmic.code(std::clamp(m[c], 0.0, 1.0), c) * 255)) << c;
  EXPECT_EQ(z[0], 255);  // the clipped channel saturates (the boost keeps it at or above 1)
}

TEST(CameraProcessing, FilmicCurveHasAToeAndAShoulder) {
  const CameraResponse filmic("filmic"), srgb("srgb");
  const double h = 1e-8;
  auto slope = [&](const CameraResponse& r, double x) { return (r.code(x + h, 1) - r.code(x, 1)) / h; };
  EXPECT_NEAR(slope(filmic, 1e-6), 0.5 * slope(srgb, 1e-6), 0.01 * slope(srgb, 1e-6));                 // toe
  EXPECT_NEAR(slope(filmic, 1 - 2 * h), 0.5 * slope(srgb, 1 - 2 * h), 0.02 * slope(srgb, 1 - 2 * h));  // shoulder
  EXPECT_GT(slope(filmic, 0.18), slope(srgb, 0.18));  // more contrast in the mid-tones
  EXPECT_NEAR(filmic.code(0.18, 0) * 255, 115, 1);
}

TEST(CameraProcessing, JpegErrorGrowsAsQualityFallsAndStaysSmallAtNinetyFive) {
  // A textured 8-bit image: the codes' RMS change through the encoder.
  cv::Mat codes(64, 64, CV_16UC3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      codes.at<cv::Vec3w>(y, x) =
          cv::Vec3w(std::uint16_t(128 + 60 * std::sin(x * 0.4)), std::uint16_t(100 + 50 * std::cos(y * 0.3)),
                    std::uint16_t((x * 7 + y * 3) % 200 + 20));
  auto rms = [&](int q) {
    const cv::Mat back = jpeg_compress(codes, q);
    cv::Mat d;
    cv::absdiff(back, codes, d);
    d.convertTo(d, CV_64F);
    return std::sqrt(cv::mean(d.mul(d))[0]);
  };
  EXPECT_LT(rms(95), 5.0);
  EXPECT_GT(rms(60), 1.5 * rms(95));
  EXPECT_THROW(jpeg_compress(codes, 0), std::invalid_argument);
}

TEST(CameraProcessing, JpegPutsSaturatedSignalBelowTheTopCode) {
  // A bright disc clipped in the raw (every channel at 1) on a blue ground: the lossless codes are
  // 255 in the disc; after JPEG some saturated pixels read lower (ringing, 4:2:0 chroma).
  const CameraProcessing p = consumer();
  const CameraResponse filmic("filmic");
  cv::Mat raw(64, 64, CV_64FC3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool disc = (x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) < 15 * 15;
      raw.at<cv::Vec3d>(y, x) = disc ? cv::Vec3d(1, 1, 1) : cv::Vec3d(0.05, 0.15, 0.35);
    }
  const cv::Mat lossless = process_raw(raw, p, filmic, 255);
  const cv::Mat jpeg = jpeg_compress(lossless, 90);
  long saturated = 0, below = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      if (lossless.at<cv::Vec3w>(y, x)[1] == 255) {
        ++saturated;
        below += jpeg.at<cv::Vec3w>(y, x)[1] < 254;
      }
  ASSERT_GT(saturated, 500);
  EXPECT_GT(below, 0);
}

TEST(CameraProcessing, LinearOutputIsWhatTheCodesInvertToWhereNothingClips) {
  // Raw exposure through the whole camera (no JPEG): inverting the tone curve gives back
  // linear_output * e * k / full_well on average.
  const CameraProcessing p = consumer();
  const CameraResponse filmic("filmic");
  cv::Mat L(48, 48, CV_32FC3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) L.at<cv::Vec3f>(y, x) = cv::Vec3f(0.2f + 0.01f * x, 0.3f, 0.25f + 0.01f * y);
  const SensorNoise noise{20000.0, 20000.0, 3.0};  // gain: L = 1 records the full well at e = 1
  const double e = 0.5;
  const cv::Mat codes = camera_bracket(L, e, noise, p, filmic, 255, 0, 3, 4);
  const cv::Mat truth = linear_output(L, p);
  double ratio = 0;
  int n = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) {
        const int z = codes.at<cv::Vec3w>(y, x)[c];
        const double t = truth.at<cv::Vec3f>(y, x)[c] * e * noise.gain / noise.full_well;
        if (z >= 250 || z < 20 || t <= 0) continue;
        ratio += filmic.relative(z / 255.0, c) / t, ++n;
      }
  ASSERT_GT(n, 3000);
  EXPECT_NEAR(ratio / n, 1.0, 0.01);
}

TEST(CameraProcessing, ASynthCaptureWithProcessingWritesTheLinearOutputAsTruth) {
  testing::TempDir dir;
  const SynthScene scene = testing::small_scene(
      ", response: filmic, format: jpeg, jpeg_quality: 85, processing: {sensitivity: [0.5, 1, 0.7], saturation: 1.2}");
  ASSERT_TRUE(scene.camera.processing);
  write_synth_capture(scene, dir.path() / "out");
  const auto truth = dir.path() / "out" / "truth";
  const YAML::Node ty = YAML::LoadFile((truth / "truth.yaml").string());
  EXPECT_EQ(ty["camera"]["jpeg_quality"].as<int>(), 85);
  EXPECT_NEAR(ty["camera"]["processing"]["white_balance_gains"][0].as<double>(), 2.0, 1e-12);
  const cv::Mat out = read_truth_image(truth / "views" / "view00_radiance.exr");
  const cv::Mat scene_L = read_truth_image(truth / "views" / "view00_scene.exr");
  // No vignetting or cast here: the truth is M (g . s . L) = M L for the automatic balance.
  const Mat3 M = scene.camera.processing->matrix();
  const cv::Vec3f s = scene_L.at<cv::Vec3f>(30, 40), o = out.at<cv::Vec3f>(30, 40);
  const Vec3 want = M * Vec3(s[0], s[1], s[2]);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(o[c], want[c], 1e-5 * (1 + std::abs(want[c])));
  EXPECT_TRUE(rsibr::read_image((dir.path() / "out" / "photos" / "view00" / "view00_b01.jpg").string()).data);
}

TEST(CameraProcessing, SpecErrorsNameTheirKey) {
  auto error_of = [](const std::string& camera_extra) {
    try {
      testing::small_scene(camera_extra);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of(", jpeg_quality: 80").find("camera.jpeg_quality"), std::string::npos);  // not a JPEG camera
  EXPECT_NE(error_of(", format: jpeg, jpeg_quality: 0").find("camera.jpeg_quality"), std::string::npos);
  EXPECT_NE(
      error_of(", processing: {saturation: 1.2, colour_matrix: [1, 0, 0, 0, 1, 0, 0, 0, 1]}").find("colour_matrix"),
      std::string::npos);
  EXPECT_NE(error_of(", processing: {sensitivity: [0, 1, 1]}").find("processing.sensitivity"), std::string::npos);
  EXPECT_NE(error_of(", processing: {tone: 1}").find("processing"), std::string::npos);
}

}  // namespace
}  // namespace rsibr
