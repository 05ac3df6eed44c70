// Camera RAW input (hdr/raw_image.h): DNGs the project writes itself (capture/dng_file.h), read back
// through LibRaw, developed to linear Rec.709 codes and merged with the identity response.
#include "hdr/raw_image.h"

#include "capture/dng_file.h"
#include "capture/synth_capture.h"
#include "capture/synth_cases.h"
#include "formats/photo_set.h"
#include "core/test_data.h"
#include "formats/truth_image.h"
#include "hdr/bracket_set.h"
#include "hdr/photo_set_merge.h"
#include "formats/image_codecs.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

namespace rsibr {
namespace {

constexpr int kBlackLevel = 512, kWhiteLevel = 16383;

// A sensor with coloured sensitivities and crosstalk between its channels (camera RGB = C *
// Rec.709), as real ones have.
Mat3 crosstalk() {
  Mat3 X;
  X << 0.80, 0.15, 0.05, 0.10, 0.80, 0.10, 0.02, 0.18, 0.80;
  return Vec3(0.5, 1.0, 0.7).asDiagonal() * X;
}

// Smooth scene radiance (Rec.709): colour ramps, a neutral strip at x < 12, black at x >= 60.
cv::Mat smooth_scene(int w, int h) {
  cv::Mat L(h, w, CV_32FC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      cv::Vec3f v(0.2f + 0.006f * float(x), 0.3f + 0.004f * float(y), 0.5f - 0.004f * float(x));
      if (x < 12) v = cv::Vec3f::all(0.15f + 0.005f * float(y));
      if (x >= 60) v = cv::Vec3f::all(0.f);
      L.at<cv::Vec3f>(y, x) = v;
    }
  return L;
}

// Raw codes of the sensor C for radiance L at exposure e (no noise): black + C L e (white - black).
cv::Mat raw_codes(const cv::Mat& L, const Mat3& C, double e) {
  cv::Mat codes(L.size(), CV_16UC3);
  for (int y = 0; y < L.rows; ++y)
    for (int x = 0; x < L.cols; ++x) {
      const cv::Vec3f p = L.at<cv::Vec3f>(y, x);
      const Vec3 cam = C * Vec3(p[0], p[1], p[2]) * e;
      for (int c = 0; c < 3; ++c)
        codes.at<cv::Vec3w>(y, x)[c] =
            std::uint16_t(kBlackLevel + std::lround(std::clamp(cam[c], 0.0, 1.0) * (kWhiteLevel - kBlackLevel)));
    }
  return codes;
}

DngInfo info_for(const Mat3& C, double t) {
  DngInfo d;
  d.black = kBlackLevel;
  d.white = kWhiteLevel;
  d.camera_from_xyz = dng_colour_matrix(C);
  const Vec3 neutral = C * Vec3::Ones();
  d.as_shot_neutral = neutral / neutral.maxCoeff();
  d.exposure_s = t;
  d.iso = 200;
  d.aperture = 4;
  return d;
}

TEST(RawFiles, RawExtensionsAreRecognisedInAnyCase) {
  EXPECT_TRUE(is_raw_file("a/b.DNG"));
  EXPECT_TRUE(is_raw_file("x.cr2"));
  EXPECT_TRUE(is_raw_file("x.Nef"));
  EXPECT_TRUE(is_raw_file("x.arw"));
  EXPECT_FALSE(is_raw_file("x.jpg"));
  EXPECT_FALSE(is_raw_file("x.tif"));
  EXPECT_FALSE(is_raw_file("dng"));
}

// Developed codes / 65535 = max(C 1) e L: the white balance (AsShotNeutral) and LibRaw's matrix
// (from ColorMatrix1) undo the crosstalk exactly, so the output is Rec.709 radiance times one
// global factor, and a neutral scene stays neutral.
TEST(RawFiles, ADngOfKnownRadianceDevelopsToThatRadianceInLinearRec709) {
  testing::TempDir dir;
  const Mat3 C = crosstalk();
  const cv::Mat L = smooth_scene(64, 48);
  const double e = 0.9;
  write_dng(dir.path() / "a.dng", bayer_mosaic(raw_codes(L, C, e), "RGGB"), info_for(C, 0.01));
  const RawImage r = read_raw_image(dir.path() / "a.dng");
  ASSERT_EQ(r.codes.cols, 64);
  ASSERT_EQ(r.codes.rows, 48);
  EXPECT_EQ(r.info.black, kBlackLevel);
  EXPECT_EQ(r.info.white, kWhiteLevel);
  EXPECT_NEAR(r.info.white_balance[0], 2.0, 1e-4);  // 1 / AsShotNeutral, the smallest 1
  EXPECT_NEAR(r.info.white_balance[1], 1.0, 1e-6);
  EXPECT_NEAR(r.info.white_balance[2], 1 / 0.7, 1e-4);
  EXPECT_NEAR(r.info.exposure_s, 0.01, 1e-6);
  const double k = (C * Vec3::Ones()).maxCoeff() * e;
  double worst = 0, worst_neutral = 0;
  for (int y = 4; y < 44; ++y)
    for (int x = 4; x < 56; ++x) {
      const cv::Vec3w o = r.codes.at<cv::Vec3w>(y, x);
      const cv::Vec3f l = L.at<cv::Vec3f>(y, x);
      if (x >= 10 && x < 14) continue;  // the neutral strip's edge: a colour step the demosaic blurs
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(o[c] / 65535.0 / (k * l[c]) - 1));
      if (x < 10)
        worst_neutral =
            std::max(worst_neutral, (std::max({o[0], o[1], o[2]}) - std::min({o[0], o[1], o[2]})) / double(o[1]));
    }
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(worst_neutral, 0.005);
  // The black level is subtracted: no light, code 0.
  for (int y = 4; y < 44; ++y)
    for (int x = 62; x < 64; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_LE(r.codes.at<cv::Vec3w>(y, x)[c], 1);
}

// Two brackets two stops apart, neither reaching the white level: the developed codes keep the
// exposure ratio (the white level is the file's, never adjusted to the data), and the second
// bracket keeps the first's white balance when asked.
TEST(RawFiles, BracketsThatDoNotReachTheWhiteLevelKeepOneScale) {
  testing::TempDir dir;
  const Mat3 C = crosstalk();
  const cv::Mat L = smooth_scene(64, 48);
  // The long one reaches 85% of the white level (a reader that rescales to the data's maximum,
  // LibRaw's default above 75%, would change its scale), the short one 21%.
  write_dng(dir.path() / "short.dng", bayer_mosaic(raw_codes(L, C, 0.425), "RGGB"), info_for(C, 0.0025));
  write_dng(dir.path() / "long.dng", bayer_mosaic(raw_codes(L, C, 1.7), "RGGB"), info_for(C, 0.01));
  const RawImage a = read_raw_image(dir.path() / "short.dng");
  const RawImage b = read_raw_image(dir.path() / "long.dng", RawOptions{a.info.white_balance});
  double sum = 0;
  int n = 0;
  for (int y = 4; y < 44; ++y)
    for (int x = 4; x < 56; ++x)
      for (int c = 0; c < 3; ++c) {
        const double za = a.codes.at<cv::Vec3w>(y, x)[c], zb = b.codes.at<cv::Vec3w>(y, x)[c];
        if (za > 200) sum += zb / za, ++n;
      }
  ASSERT_GT(n, 5000);
  EXPECT_NEAR(sum / n, 4.0, 0.01);
  double top = 0;
  cv::minMaxLoc(b.codes.reshape(1), nullptr, &top);
  EXPECT_LT(top, 65535);  // nothing clipped
  EXPECT_LT((a.info.white_balance - b.info.white_balance).norm(), 1e-5);
}

// Sensor saturation: every pixel whose camera channel reached the white level, and the 2 px the
// demosaic spreads it over, is in the saturation mask; the clipped channels carry code 65535;
// pixels further away are neither.
TEST(RawFiles, TheWhiteLevelIsSaturationAndIsMarkedWithTheTopCode) {
  testing::TempDir dir;
  const Mat3 C = crosstalk();
  cv::Mat L = smooth_scene(64, 48);
  for (int y = 20; y < 28; ++y)
    for (int x = 30; x < 38; ++x) L.at<cv::Vec3f>(y, x) = cv::Vec3f(4, 3, 2);  // a lamp, far above the white level
  write_dng(dir.path() / "lamp.dng", bayer_mosaic(raw_codes(L, C, 0.9), "RGGB"), info_for(C, 0.01));
  const RawImage r = read_raw_image(dir.path() / "lamp.dng");
  auto top = [&](int x, int y) {
    const cv::Vec3w o = r.codes.at<cv::Vec3w>(y, x);
    return o[0] == 65535 || o[1] == 65535 || o[2] == 65535;
  };
  ASSERT_EQ(r.saturated.type(), CV_8UC1);
  for (int y = 18; y < 30; ++y)
    for (int x = 28; x < 40; ++x) EXPECT_TRUE(r.saturated.at<unsigned char>(y, x)) << x << "," << y;
  for (int y = 21; y < 27; ++y)
    for (int x = 31; x < 37; ++x) EXPECT_TRUE(top(x, y)) << x << "," << y;
  for (int y = 4; y < 44; ++y)
    for (int x = 4; x < 56; ++x)
      if (y < 14 || y >= 34 || x < 24 || x >= 44) {
        EXPECT_FALSE(top(x, y)) << x << "," << y;
        EXPECT_FALSE(r.saturated.at<unsigned char>(y, x)) << x << "," << y;
      }
  EXPECT_GE(r.info.saturated_fraction, 144.0 / (64 * 48));
  EXPECT_LT(r.info.saturated_fraction, 400.0 / (64 * 48));
}

TEST(RawFiles, TheDevelopingStepMasksExactlyTheClippedNeighbourhood) {
  cv::Mat cam(20, 20, CV_16UC3, cv::Scalar(1000, 2000, 3000));
  cam.at<cv::Vec3w>(10, 10) = cv::Vec3w(65535, 2000, 3000);
  cv::Mat mask;
  const cv::Mat out = camera_to_output_codes(cam, Mat3::Identity(), mask);
  EXPECT_EQ(cv::countNonZero(mask), 25);
  EXPECT_TRUE(mask.at<unsigned char>(8, 12));                          // 2 px away: masked
  EXPECT_FALSE(mask.at<unsigned char>(7, 10));                         // 3 px away: not
  EXPECT_EQ(out.at<cv::Vec3w>(10, 10), cv::Vec3w(65535, 2000, 3000));  // its clipped channel only
  EXPECT_EQ(out.at<cv::Vec3w>(8, 12), cv::Vec3w(1000, 2000, 3000));    // the ring keeps its values
  // The matrix: out of range is clamped (negative to 0, above the top to the top); a clipped
  // camera channel is at the top whatever the matrix makes of it.
  Mat3 M;
  M << 2, -1, 0, 0, 1, 0, -1, 0, 1;
  const cv::Mat o2 = camera_to_output_codes(cv::Mat(2, 2, CV_16UC3, cv::Scalar(40000, 1000, 100)), M, mask);
  EXPECT_EQ(o2.at<cv::Vec3w>(0, 0), cv::Vec3w(65535, 1000, 0));
  EXPECT_EQ(cv::countNonZero(mask), 0);
  M << 0.5, 0.5, 0, 0, 1, 0, 0, 0, 1;
  const cv::Mat o3 = camera_to_output_codes(cv::Mat(2, 2, CV_16UC3, cv::Scalar(65535, 1000, 100)), M, mask);
  EXPECT_EQ(o3.at<cv::Vec3w>(1, 1), cv::Vec3w(65535, 1000, 100));
  EXPECT_EQ(cv::countNonZero(mask), 4);
}

TEST(RawFiles, ACorruptRawFileIsAnErrorNamingIt) {
  testing::TempDir dir;
  {
    std::ofstream f(dir.file("bad.nef"));
    f << "this is not a raw file";
  }
  try {
    read_raw_image(dir.path() / "bad.nef");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.nef"), std::string::npos) << e.what();
  }
  // A DNG cut short.
  const Mat3 C = crosstalk();
  write_dng(dir.path() / "whole.dng", bayer_mosaic(raw_codes(smooth_scene(64, 48), C, 0.5), "RGGB"), info_for(C, 0.01));
  std::ifstream in(dir.file("whole.dng"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  {
    std::ofstream out(dir.file("cut.dng"), std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size() / 3));
  }
  EXPECT_THROW(read_raw_image(dir.path() / "cut.dng"), std::runtime_error);
}

TEST(RawFiles, TheExposureComesFromTheFileWhenTheYamlLeavesItOut) {
  testing::TempDir dir;
  const Mat3 C = crosstalk();
  const cv::Mat L = smooth_scene(64, 48);
  PhotoView v;
  v.name = "v";
  const double times[] = {0.01, 0.0025};
  for (int j = 0; j < 2; ++j) {
    const auto f = dir.path() / ("b" + std::to_string(j) + ".dng");
    write_dng(f, bayer_mosaic(raw_codes(L, C, times[j] * 40), "RGGB"), info_for(C, times[j]));
    v.brackets.push_back({f, std::nullopt, std::nullopt, std::nullopt});
  }
  const BracketSet b = load_brackets(v);
  ASSERT_TRUE(b.raw);
  ASSERT_EQ(b.raw_info.size(), 2u);
  EXPECT_EQ(b.max_code, 65535);
  EXPECT_NEAR(b.metadata[0].exposure_s, 0.0025, 1e-7);  // sorted by exposure
  EXPECT_NEAR(b.metadata[1].exposure_s, 0.01, 1e-7);
  EXPECT_NEAR(b.metadata[0].aperture, 4, 1e-6);
  EXPECT_NEAR(b.metadata[0].iso, 200, 1e-9);
  EXPECT_EQ(b.metadata[0].source, "raw+exif");  // LibRaw leaves the IFD 0 ISO to exiv2
  EXPECT_NEAR(b.exposures[0], 0.0025 * 2 / 16, 1e-8);
  // The exposure extremes (1/32000 s to 60 s) survive the file's rationals.
  for (const double t : {1.0 / 32000, 60.0}) {
    PhotoView one;
    one.name = "x";
    const auto f = dir.path() / "extreme.dng";
    write_dng(f, bayer_mosaic(raw_codes(L, C, 0.3), "RGGB"), info_for(C, t));
    one.brackets.push_back({f, std::nullopt, std::nullopt, std::nullopt});
    EXPECT_NEAR(load_brackets(one).metadata[0].exposure_s / t, 1.0, 1e-6) << t;
  }
  // A view mixing RAW and other images is refused with a message saying so.
  rsibr::write_image(dir.file("c.png"), cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(100)));
  v.brackets.push_back({dir.path() / "c.png", 0.04, 200.0, 4.0});
  try {
    load_brackets(v);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("RAW"), std::string::npos) << e.what();
  }
}

// The whole way: rsibr synth writes DNG brackets (a 14-bit RGGB sensor with coloured
// sensitivities, its automatic white balance as AsShotNeutral, Poisson and read noise), the photo
// set's response is the identity without a fit, and the merge recovers the truth's radiance; the
// sun, clipped in every bracket, is flagged, and its clipped channels are never above the truth.
TEST(RawFiles, SynthesizedDngBracketsMergeToTheTrueRadianceWithTheIdentityResponse) {
  testing::TempDir dir;
  const std::string camera = ", format: dng, processing: {sensitivity: [0.5, 1, 0.7]}";
  // Metered, then exposed three stops brighter, so that the sun clips in every bracket.
  write_synth_capture(testing::small_scene(camera), dir.path() / "metered");
  const double metered =
      YAML::LoadFile((dir.path() / "metered" / "truth" / "truth.yaml").string())["camera"]["gain"].as<double>();
  const SynthScene scene = testing::small_scene(camera + ", gain: " + std::to_string(8 * metered));
  write_synth_capture(scene, dir.path() / "out");
  const PhotoSet set = load_photo_set(dir.path() / "out" / "photos");
  std::vector<const PhotoView*> views;
  for (const PhotoView& v : set.views) views.push_back(&v);
  const PhotoSetResponse psr = recover_photo_set_response(views, RecoveryOptions{}, Alignment::off);
  EXPECT_EQ(psr.recovery.curve.model, "identity");
  EXPECT_NE(psr.recovery.chosen.find("RAW"), std::string::npos);
  EXPECT_EQ(psr.recovery.curve.saturation_code(1), 65535);
  const YAML::Node ty = YAML::LoadFile((dir.path() / "out" / "truth" / "truth.yaml").string());
  const double k = ty["camera"]["gain_normalised"].as<double>();
  for (const PhotoView& v : set.views) {
    const ViewMerge m = merge_photo_view(v, psr.recovery.curve, psr.noise, Alignment::automatic);
    const cv::Mat truth = read_truth_image(dir.path() / "out" / "truth" / "views" / (v.name + "_radiance.exr"));
    std::vector<double> ratios[3];
    long clipped = 0, clipped_above = 0;
    const cv::Mat& shortest = m.brackets.codes[0];
    for (int y = 2; y < truth.rows - 2; ++y)
      for (int x = 2; x < truth.cols - 2; ++x) {
        const cv::Vec3f t = truth.at<cv::Vec3f>(y, x) * float(k), o = m.image.radiance.at<cv::Vec3f>(y, x);
        const bool is_clipped = m.image.flags.at<unsigned char>(y, x) & kClipped;
        for (int c = 0; c < 3; ++c) {
          EXPECT_TRUE(std::isfinite(o[c]) && o[c] >= 0);
          if (is_clipped) {
            // A channel the sensor clipped even in the shortest bracket: a lower bound.
            if (shortest.at<cv::Vec3w>(y, x)[c] != 65535) continue;
            ++clipped;
            clipped_above += o[c] > t[c] * 1.02f;
          } else if (t[c] > 1e-3f) {
            ratios[c].push_back(o[c] / t[c]);
          }
        }
      }
    for (auto& r : ratios) {
      ASSERT_GT(r.size(), 2000u);
      std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
      EXPECT_NEAR(r[r.size() / 2], 1.0, 0.01) << v.name;
    }
    EXPECT_GT(clipped, 0) << v.name << ": the sun is clipped in every bracket";
    EXPECT_EQ(clipped_above, 0) << v.name;
  }
}

}  // namespace
}  // namespace rsibr
