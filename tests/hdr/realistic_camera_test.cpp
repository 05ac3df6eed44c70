// Response recovery and the merge on shoots through a camera that behaves like a consumer one
// (tests/hdr/camera_shoot.h: raw sensitivities, white balance, a saturating colour matrix, a tone
// curve with a toe and a shoulder, JPEG at quality 90), of two CC0 environments, three views each:
// neutral stays neutral, the model choice does not flip between seeds, saturation is measured so
// that JPEG cannot fool it, the honesty channels are calibrated, and the errors are at or below
// OpenCV's Debevec and Robertson in the same run.
#include "hdr/camera_shoot.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"

#include "core/test_data.h"

#include <gtest/gtest.h>
#include <opencv2/photo.hpp>

#include <cstdio>
#include <map>
#include <memory>
#include <tuple>

namespace rsibr {
namespace {

struct ShootRun {
  testing::Shoot shoot;
  ResponseRecovery recovery;
  NoiseModel noise;
  std::vector<MergedImage> merged;
  testing::ShootErrors errors;
  double ghost_fraction = 0, spread = 0;
};

std::vector<const BracketSet*> views_of(const testing::Shoot& sh) {
  std::vector<const BracketSet*> v;
  for (const auto& b : sh.views) v.push_back(&b);
  return v;
}

std::vector<cv::Mat> radiances(const std::vector<MergedImage>& m) {
  std::vector<cv::Mat> r;
  for (const auto& x : m) r.push_back(x.radiance);
  return r;
}

testing::ShootSpec spec(const std::string& env, int jpeg_quality, std::uint64_t seed) {
  testing::ShootSpec s;
  s.env = (testing::assets_dir() / "hdri" / (env + ".exr")).string();
  s.jpeg_quality = jpeg_quality;
  s.seed = seed;
  return s;
}

ShootRun run(const testing::ShootSpec& s) {
  ShootRun r;
  r.shoot = testing::shoot(s);
  const auto views = views_of(r.shoot);
  r.recovery = recover_response(views);
  r.noise = estimate_noise(views, r.recovery.curve);
  long ghost = 0, pixels = 0;
  for (const auto& b : r.shoot.views) {
    r.merged.push_back(merge_brackets(b, r.recovery.curve, r.noise));
    ghost += r.merged.back().ghost;
    pixels += long(b.rows()) * b.cols();
  }
  r.errors = testing::shoot_errors(radiances(r.merged), r.shoot);
  r.ghost_fraction = double(ghost) / double(pixels);
  r.spread = testing::normalised_spread(r.merged, r.shoot, r.errors.scale);
  return r;
}

// Runs are shared by the tests of this file (each takes seconds).
const ShootRun& cached(const std::string& env, int jpeg_quality, std::uint64_t seed) {
  static std::map<std::tuple<std::string, int, std::uint64_t>, std::unique_ptr<ShootRun>> cache;
  auto& slot = cache[{env, jpeg_quality, seed}];
  if (!slot) slot = std::make_unique<ShootRun>(run(spec(env, jpeg_quality, seed)));
  return *slot;
}

class RealisticCamera : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(testing::assets_dir() / "hdri" / "park.exr")) GTEST_SKIP() << testing::kNoAssets;
  }
  // The two environments (a sunlit park, an interior) as PNG and as JPEG at quality 90.
  static std::vector<std::tuple<std::string, int>> shoots() {
    return {{"park", 0}, {"park", 90}, {"lab", 0}, {"lab", 90}};
  }
  static std::string name(const std::string& env, int q) { return env + (q ? " JPEG" : " PNG"); }
};

TEST_F(RealisticCamera, ANeutralPatchStaysNeutralWithinTwoPercent) {
  for (const auto& [env, q] : shoots()) {
    const ShootRun& r = cached(env, q, 1);
    std::printf("%s: neutral patch R/G %.4f B/G %.4f, clipped at or below truth %.4f, ghosts %.5f, spread %.3f, %s\n",
                name(env, q).c_str(), r.errors.patch_rg, r.errors.patch_bg, r.errors.clipped_at_or_below,
                r.ghost_fraction, r.spread, r.recovery.chosen.c_str());
    EXPECT_NEAR(r.errors.patch_rg, 1.0, 0.02) << name(env, q);
    EXPECT_NEAR(r.errors.patch_bg, 1.0, 0.02) << name(env, q);
  }
}

TEST_F(RealisticCamera, TheAutomaticChoiceIsTheSameForEverySeed) {
  for (const auto& [env, q] : std::vector<std::tuple<std::string, int>>{{"park", 90}, {"lab", 0}}) {
    const std::string first = cached(env, q, 1).recovery.chosen;
    EXPECT_NE(first.find("(shared)"), std::string::npos) << name(env, q) << ": " << first;  // in-camera JPEG: one curve
    for (std::uint64_t seed = 2; seed <= 3; ++seed)
      EXPECT_EQ(cached(env, q, seed).recovery.chosen, first) << name(env, q) << " seed " << seed;
    EXPECT_FALSE(cached(env, q, 1).recovery.near_tie) << cached(env, q, 1).recovery.warning;
  }
}

TEST_F(RealisticCamera, ClippedValuesAreALowerBoundForNinetySevenPercent) {
  for (const auto& [env, q] : shoots()) EXPECT_GE(cached(env, q, 1).errors.clipped_at_or_below, 0.97) << name(env, q);
}

TEST_F(RealisticCamera, SaturationIsMeasuredBelowTheTopCodeForJpegAndAtItForPng) {
  for (const auto& [env, q] : shoots()) {
    const SaturationLevel& s = cached(env, q, 1).recovery.saturation;
    EXPECT_EQ(s.source, "detected") << name(env, q);
    for (int c = 0; c < 3; ++c) {
      if (q == 0)
        EXPECT_EQ(s.code[std::size_t(c)], default_saturation_code(255)) << name(env, q);
      else
        EXPECT_LT(s.code[std::size_t(c)], default_saturation_code(255)) << name(env, q) << " channel " << c;
      EXPECT_GT(s.code[std::size_t(c)], 200) << name(env, q);
    }
  }
}

TEST_F(RealisticCamera, GhostFlagsCoverUnderHalfAPercentOfAStillScene) {
  for (const auto& [env, q] : shoots()) EXPECT_LT(cached(env, q, 1).ghost_fraction, 0.005) << name(env, q);
}

TEST_F(RealisticCamera, TheVarianceChannelsNormalisedSpreadIsWithinPointEightAndOnePointTwoFive) {
  for (const auto& [env, q] : shoots()) {
    const double s = cached(env, q, 1).spread;
    EXPECT_GE(s, 0.8) << name(env, q);
    EXPECT_LE(s, 1.25) << name(env, q);
  }
}

TEST_F(RealisticCamera, TheNoiseModelAndTheSamplesComeFromEveryView) {
  const ShootRun& r = cached("lab", 90, 1);
  EXPECT_EQ(r.recovery.views, 3);
  EXPECT_EQ(r.noise.views, 3);
  EXPECT_EQ(r.noise.source, "estimated");
  EXPECT_GE(r.recovery.train_samples + r.recovery.held_out_samples, 10000);
  BracketStatistics st(3);
  for (const auto& b : r.shoot.views) st.add(b);
  const ResponseSamples s = select_samples(st, r.recovery.saturation.code);
  std::vector<int> per_view(3, 0);
  for (int v : s.view) ++per_view[std::size_t(v)];
  for (int v = 0; v < 3; ++v) EXPECT_GT(per_view[std::size_t(v)], int(s.view.size()) / 10) << "view " << v;
  // A lossy file's compression error is modelled (a lossless one's is not).
  for (int c = 0; c < 3; ++c) EXPECT_GT(r.noise.texture[std::size_t(c)] + r.noise.code[std::size_t(c)], 0.0);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(cached("lab", 0, 1).noise.texture[std::size_t(c)], 0.0);
}

TEST_F(RealisticCamera, TheCurveHasNoRippleAtTheExposureSteps) {
  // Two-stop brackets leave a log-periodic ambiguity the data cannot see; the smoothness prior
  // must not let it through: the recovered curve over the true one, normalised at the middle code,
  // stays within 1.5% over codes 16-240 (the tone curve's inverse is the truth).
  for (const auto& [env, q] : std::vector<std::tuple<std::string, int>>{{"park", 0}, {"lab", 0}}) {
    const ResponseCurve& curve = cached(env, q, 1).recovery.curve;
    const CameraResponse filmic("filmic");
    for (int c = 0; c < 3; ++c) {
      const double mid = curve.linear(c, 127.5) / filmic.relative(0.5, c);
      double worst = 0;
      for (int z = 16; z <= 240; ++z)
        worst = std::max(worst, std::abs(curve.linear(c, z) / filmic.relative(z / 255.0, c) / mid - 1));
      EXPECT_LT(worst, 0.015) << name(env, q) << " channel " << c;
    }
  }
}

// OpenCV's calibration and merge on the same brackets (all views side by side, so it sees every
// view too): its Debevec and Robertson.
std::vector<cv::Mat> opencv_merge(const testing::Shoot& sh, bool robertson) {
  const std::vector<cv::Mat> stack = testing::side_by_side_bgr(sh);
  const std::vector<float> times(sh.exposures.begin(), sh.exposures.end());
  cv::Mat response, hdr;
  if (robertson) {
    cv::createCalibrateRobertson()->process(stack, response, times);
    cv::createMergeRobertson()->process(stack, hdr, times, response);
  } else {
    cv::createCalibrateDebevec()->process(stack, response, times);
    cv::createMergeDebevec()->process(stack, hdr, times, response);
  }
  cv::cvtColor(hdr, hdr, cv::COLOR_BGR2RGB);
  std::vector<cv::Mat> out;
  const int W = sh.views.front().cols(), H = sh.views.front().rows();
  for (std::size_t v = 0; v < sh.views.size(); ++v) out.push_back(hdr(cv::Rect(int(v) * W, 0, W, H)).clone());
  return out;
}

TEST_F(RealisticCamera, MidToneAndColourErrorsAreAtOrBelowOpenCVsInTheSameRun) {
  for (const auto& [env, q] : std::vector<std::tuple<std::string, int>>{{"park", 90}, {"lab", 0}}) {
    const ShootRun& r = cached(env, q, 1);
    for (bool robertson : {false, true}) {
      const testing::ShootErrors cv_errors = testing::shoot_errors(opencv_merge(r.shoot, robertson), r.shoot);
      const std::string who = name(env, q) + (robertson ? " vs OpenCV Robertson" : " vs OpenCV Debevec");
      std::printf("%s: mid-tone %.4f vs %.4f stops, colour ratio %.4f vs %.4f stops\n", who.c_str(),
                  r.errors.stops[testing::kMid], cv_errors.stops[testing::kMid], r.errors.colour_stops,
                  cv_errors.colour_stops);
      EXPECT_LE(r.errors.stops[testing::kMid], cv_errors.stops[testing::kMid]) << who;
      EXPECT_LE(r.errors.colour_stops, cv_errors.colour_stops) << who;
    }
  }
}

TEST_F(RealisticCamera, AGivenSaturationCodeIsUsed) {
  const testing::Shoot& sh = cached("lab", 90, 1).shoot;
  RecoveryOptions o;
  o.model = "debevec";
  o.channels = "shared";
  o.saturation_code = {230, 231, 232};
  const ResponseRecovery r = recover_response(views_of(sh), o);
  EXPECT_EQ(r.saturation.source, "given");
  for (int c = 0; c < 3; ++c) EXPECT_EQ(r.curve.saturation_code(c), 230 + c);
  // Flat from there up: a clipped value is at most X(saturation code) / e.
  for (int c = 0; c < 3; ++c) EXPECT_EQ(r.curve.linear(c, 255), r.curve.linear(c, 230 + c));
}

TEST_F(RealisticCamera, ACameraWithPerChannelCurvesGetsPerChannelCurves) {
  // No colour matrix, capture's film-like per-channel response: one shared curve cannot fit it,
  // and the preference for a shared curve must not hide that.
  testing::ShootSpec s = spec("lab", 0, 1);
  s.response = "measured";
  s.processing = CameraProcessing{};
  s.views = 2;
  const testing::Shoot sh = testing::shoot(s);
  const ResponseRecovery r = recover_response(views_of(sh));
  EXPECT_NE(r.chosen.find("(per channel)"), std::string::npos) << r.chosen;
}

}  // namespace
}  // namespace rsibr
