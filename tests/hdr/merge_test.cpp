// The merge: unbiased, within 10% of the noise-optimal bound, clipped pixels flagged and never
// invented, exposures 1/32000 s to 60 s, all-black / all-white inputs, ghosts, determinism.
#include "hdr/bracket_synth.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace rsibr {
namespace {

using testing::BracketCamera;

NoiseModel true_noise(const BracketCamera& cam) {
  NoiseModel n;
  for (int c = 0; c < 3; ++c) n.shot[std::size_t(c)] = cam.shot(), n.read[std::size_t(c)] = cam.read();
  n.source = "given";
  return n;
}

bool all_finite(const cv::Mat& m) { return cv::checkRange(m, true, nullptr, -FLT_MAX, FLT_MAX); }

// A scene of `levels` grey-ish radiance levels, each filling `per_level` pixels (one column block).
cv::Mat level_scene(const std::vector<double>& levels, int per_level) {
  cv::Mat L(per_level, int(levels.size()), CV_64FC3);
  for (int x = 0; x < L.cols; ++x)
    for (int r = 0; r < L.rows; ++r) L.at<cv::Vec3d>(r, x) = cv::Vec3d(0.9, 1.0, 1.1) * levels[std::size_t(x)];
  return L;
}

// The noise-optimal variance of an unbiased combination: 1 / sum_j e_j^2 / var(X_j), over the
// brackets that do not saturate (X = L e k; the merge's unit is X / e, so its truth is L k).
// A bracket counts when its brightest channel (Lk_max) does not saturate: the merge's rule.
double optimal_variance(double Lk, double Lk_max, const std::vector<double>& e, const BracketCamera& cam,
                        double sat_X) {
  double info = 0;
  for (double ej : e) {
    const double X = Lk * ej;
    if (Lk_max * ej >= sat_X) continue;
    info += ej * ej / (cam.shot() * X + cam.read() + 1.0 / (12.0 * 65535.0 * 65535.0));
  }
  return 1.0 / info;
}

// True when bracket saturation is ambiguous for this level (some bracket's X within 6 sigma of
// the threshold): the truncation there is a selection effect, not the estimator's bias.
bool near_saturation(double Lk, const std::vector<double>& e, const BracketCamera& cam, double sat_X) {
  for (double ej : e) {
    const double X = Lk * ej;
    if (std::abs(X - sat_X) < 6 * std::sqrt(cam.shot() * X + cam.read())) return true;
  }
  return false;
}

struct LevelStats {
  double max_bias_sigmas = 0;  // worst |mean error| / standard error of the mean
  double mse_over_bound = 0;   // mean over levels and channels of MSE / optimal variance
  int levels_used = 0;
};

LevelStats level_stats(const MergedImage& m, const std::vector<double>& levels, const std::vector<double>& e,
                       const BracketCamera& cam, double sat_X) {
  LevelStats s;
  double ratio_sum = 0;
  int ratio_n = 0;
  for (int x = 0; x < int(levels.size()); ++x)
    for (int c = 0; c < 3; ++c) {
      const double truth = levels[std::size_t(x)] * (0.9 + 0.1 * c) * cam.gain;
      const double brightest = levels[std::size_t(x)] * 1.1 * cam.gain;
      if (near_saturation(brightest, e, cam, sat_X) || brightest * e[0] >= sat_X) continue;
      const double bound = optimal_variance(truth, brightest, e, cam, sat_X);
      double sum = 0, sq = 0;
      const int n = m.radiance.rows;
      for (int r = 0; r < n; ++r) {
        const double d = m.radiance.at<cv::Vec3f>(r, x)[c] - truth;
        sum += d, sq += d * d;
      }
      const double mean = sum / n;
      s.max_bias_sigmas = std::max(s.max_bias_sigmas, std::abs(mean) / std::sqrt(bound / n));
      ratio_sum += (sq / n) / bound;
      ++ratio_n;
    }
  s.levels_used = ratio_n;
  s.mse_over_bound = ratio_sum / std::max(1, ratio_n);
  return s;
}

std::vector<double> log_levels(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(std::pow(10.0, lo + (hi - lo) * i / (n - 1)));
  return v;
}

TEST(Merge, MergedRadianceIsUnbiasedAndWithinTenPercentOfTheNoiseOptimalBound) {
  BracketCamera cam;  // 16-bit linear, shot + read noise
  cam.gain = 0.5;
  const auto e = testing::exposure_series(1.0 / 1000, 4.0, 7);
  const auto levels = log_levels(-1.5, 3.0, 48);
  const cv::Mat L = level_scene(levels, 400);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 11), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam));
  const double sat_X = double(default_saturation_code(65535)) / 65535.0;
  const LevelStats s = level_stats(m, levels, e, cam, sat_X);
  EXPECT_GT(s.levels_used, 100);
  EXPECT_LT(s.max_bias_sigmas, 4.5);  // 4.5 standard errors, over ~140 level-channels
  EXPECT_LT(s.mse_over_bound, 1.10);  // error within 10% of the bound (in variance)
  EXPECT_GT(s.mse_over_bound, 0.90);  // and the bound is a bound (a check on the test itself)
}

TEST(Merge, WeightsFromTheMeasuredSignalAreBiasedLowAndThePilotPassRemovesIt) {
  // Few photo-electrons: weighting by the measured X favours low draws. The pilot pass must matter.
  BracketCamera cam;
  cam.full_well = 200;
  cam.read_sigma = 1e-3;
  const auto e = testing::exposure_series(1.0 / 100, 2.0, 5);
  const auto levels = log_levels(0.0, 1.5, 12);
  const cv::Mat L = level_scene(levels, 2000);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 12), e);
  const double sat_X = double(default_saturation_code(65535)) / 65535.0;
  MergeOptions naive;
  naive.pilot_pass = false;
  const LevelStats with_pilot =
      level_stats(merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam)), levels, e, cam, sat_X);
  const LevelStats without =
      level_stats(merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam), naive), levels, e, cam, sat_X);
  EXPECT_LT(with_pilot.max_bias_sigmas, 4.5);
  EXPECT_GT(without.max_bias_sigmas, 6.0);
}

TEST(Merge, PixelsClippedInEveryBracketAreFlaggedAndNeverExceedTheTruth) {
  BracketCamera cam;
  const auto e = testing::exposure_series(1.0 / 100, 4.0, 5);
  // Left half: moderate radiance; right half: a sun 1000x beyond the shortest bracket's saturation.
  cv::Mat L(16, 32, CV_64FC3, cv::Scalar::all(5.0));
  L(cv::Rect(16, 0, 16, 16)).setTo(cv::Scalar(1e5, 5e4, 2e4));
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 13), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam));
  EXPECT_EQ(m.clipped, 16 * 16);
  for (int r = 0; r < 16; ++r)
    for (int x = 0; x < 32; ++x) {
      const bool sun = x >= 16;
      EXPECT_EQ((m.flags.at<unsigned char>(r, x) & kClipped) != 0, sun);
      if (!sun) continue;
      for (int c = 0; c < 3; ++c) {
        const float v = m.radiance.at<cv::Vec3f>(r, x)[c];
        EXPECT_LE(v, L.at<cv::Vec3d>(r, x)[c]);   // a lower bound, never invented
        EXPECT_NEAR(v, 1.0 / e[0], 1e-3 / e[0]);  // exactly what the shortest bracket saw
      }
    }
  EXPECT_TRUE(all_finite(m.radiance));
  EXPECT_TRUE(all_finite(m.variance));
}

TEST(Merge, ABracketSaturatedInAnyChannelIsExcludedSoHueIsKept) {
  // An orange light: red saturates one bracket before green and blue. Keeping the clipped red
  // with the unclipped green would pull the merge toward a pinker, darker red.
  BracketCamera cam;
  cam.max_code = 255;
  cam.full_well = 0;
  cam.read_sigma = 0;
  const auto e = testing::exposure_series(1.0 / 64, 2.0, 6);
  cv::Mat L(8, 8, CV_64FC3, cv::Scalar(40.0, 12.0, 3.0));
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 14), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(255), NoiseModel{});
  const cv::Vec3f v = m.radiance.at<cv::Vec3f>(4, 4);
  EXPECT_NEAR(v[0] / v[1], 40.0 / 12.0, 0.02 * 40.0 / 12.0);
  EXPECT_NEAR(v[0], 40.0, 0.02 * 40.0);
  // Green's variance is that of the brackets where no channel saturates: the bracket where only
  // red saturates is not used for green either.
  const NoiseModel nm;
  const double q = 1.0 / (12.0 * 255 * 255), sat_X = 254.0 / 255.0;
  double info_all = 0, info_kept = 0;
  int kept = 0, green_unsaturated = 0;
  for (double ej : e) {
    const double G = v[1];
    const double w = ej * ej / (nm.shot[1] * G * ej + nm.read[1] + q);
    if (12.0 * ej < sat_X) info_all += w, ++green_unsaturated;
    if (40.0 * ej < sat_X) info_kept += w, ++kept;
  }
  ASSERT_LT(kept, green_unsaturated);  // the scene does what the test needs
  EXPECT_NEAR(m.variance.at<cv::Vec3f>(4, 4)[1], 1.0 / info_kept, 1e-3 / info_kept);
  EXPECT_GT(1.0 / info_kept, 1.5 / info_all);
  EXPECT_TRUE(all_finite(merge_hat_weighted(b, ResponseCurve::identity(255))));
}

TEST(Merge, ExposuresFrom1Over32000To60SecondsMergeWithoutNanAndUnbiased) {
  BracketCamera cam;
  const std::vector<double> e = {1.0 / 32000, 1.0 / 4000, 1.0 / 500, 1.0 / 60, 1.0 / 8, 1.0, 8.0, 60.0};
  const auto levels = log_levels(-5.0, 4.0, 40);
  const cv::Mat L = level_scene(levels, 300);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 15), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam));
  EXPECT_TRUE(all_finite(m.radiance));
  EXPECT_TRUE(all_finite(m.variance));
  const double sat_X = double(default_saturation_code(65535)) / 65535.0;
  const LevelStats s = level_stats(m, levels, e, cam, sat_X);
  EXPECT_GT(s.levels_used, 60);
  EXPECT_LT(s.max_bias_sigmas, 4.5);
  EXPECT_LT(s.mse_over_bound, 1.10);
}

TEST(Merge, AllBlackAndAllWhiteInputsAreFlaggedNeverNan) {
  const auto e = testing::exposure_series(0.01, 4.0, 4);
  for (int max_code : {255, 65535}) {
    const int type = max_code == 255 ? CV_8UC3 : CV_16UC3;
    const std::vector<cv::Mat> black(4, cv::Mat(8, 8, type, cv::Scalar::all(0)));
    const MergedImage mb = merge_brackets(make_brackets(black, e), ResponseCurve::identity(max_code), NoiseModel{});
    EXPECT_EQ(mb.black, 64);
    EXPECT_EQ(mb.clipped, 0);
    EXPECT_EQ(cv::countNonZero(mb.radiance.reshape(1)), 0);
    EXPECT_TRUE(all_finite(mb.variance));
    const std::vector<cv::Mat> white(4, cv::Mat(8, 8, type, cv::Scalar::all(max_code)));
    const MergedImage mw = merge_brackets(make_brackets(white, e), ResponseCurve::identity(max_code), NoiseModel{});
    EXPECT_EQ(mw.clipped, 64);
    EXPECT_TRUE(all_finite(mw.radiance));
    EXPECT_TRUE(all_finite(mw.variance));
    EXPECT_NEAR(mw.radiance.at<cv::Vec3f>(0, 0)[1], 1.0 / e[0], 1e-6 / e[0]);
  }
}

TEST(Merge, SameInputsGiveTheSameBytes) {
  BracketCamera cam;
  const auto e = testing::exposure_series(1.0 / 100, 4.0, 5);
  const cv::Mat L = testing::ramp_scene(40, 60, -2, 2);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 16), e);
  const BracketSet b2 = make_brackets(testing::synthesize(L, e, cam, 16), e);
  const MergedImage m1 =
      merge_brackets(b, ResponseCurve::identity(65535), estimate_noise(b, ResponseCurve::identity(65535), 65209));
  const MergedImage m2 =
      merge_brackets(b2, ResponseCurve::identity(65535), estimate_noise(b2, ResponseCurve::identity(65535), 65209));
  ASSERT_EQ(m1.radiance.total(), m2.radiance.total());
  EXPECT_EQ(std::memcmp(m1.radiance.data, m2.radiance.data, m1.radiance.total() * 12), 0);
  EXPECT_EQ(std::memcmp(m1.variance.data, m2.variance.data, m1.variance.total() * 12), 0);
  EXPECT_EQ(std::memcmp(m1.flags.data, m2.flags.data, m1.flags.total()), 0);
}

TEST(Merge, VarianceChannelMatchesTheObservedScatter) {
  BracketCamera cam;
  const auto e = testing::exposure_series(1.0 / 1000, 4.0, 6);
  const auto levels = log_levels(-1.0, 2.5, 16);
  const BracketSet b = make_brackets(testing::synthesize(level_scene(levels, 500), e, cam, 17), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam));
  for (int x = 0; x < int(levels.size()); ++x) {
    double sum = 0, sq = 0, mean_var = 0;
    for (int r = 0; r < m.radiance.rows; ++r) {
      const double v = m.radiance.at<cv::Vec3f>(r, x)[1];
      sum += v, sq += v * v;
      mean_var += m.variance.at<cv::Vec3f>(r, x)[1];
    }
    const double n = m.radiance.rows;
    const double scatter = (sq - sum * sum / n) / (n - 1);
    mean_var /= n;
    EXPECT_NEAR(scatter / mean_var, 1.0, 0.2) << "level " << levels[std::size_t(x)];
  }
}

TEST(Merge, EstimatedNoiseModelMatchesTheCamera) {
  BracketCamera cam;
  cam.full_well = 5000;
  cam.read_sigma = 4e-4;
  const auto e = testing::exposure_series(1.0 / 1000, 4.0, 6);
  const cv::Mat L = testing::ramp_scene(200, 300, -2, 2.5);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 18), e);
  const NoiseModel n = estimate_noise(b, ResponseCurve::identity(65535), default_saturation_code(65535));
  EXPECT_EQ(n.source, "estimated");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(n.shot[std::size_t(c)] / cam.shot(), 1.0, 0.1);
    EXPECT_NEAR(n.read[std::size_t(c)] / cam.read(), 1.0, 0.3);
  }
}

TEST(Merge, GhostsAreFlaggedWhereTheSceneMovedAndRarelyElsewhere) {
  BracketCamera cam;
  const auto e = testing::exposure_series(1.0 / 100, 4.0, 5);
  const cv::Mat L = testing::ramp_scene(64, 64, -1, 1.5);
  auto imgs = testing::synthesize(L, e, cam, 19);
  const MergedImage still = merge_brackets(make_brackets(imgs, e), ResponseCurve::identity(65535), true_noise(cam));
  EXPECT_LT(still.ghost, long(0.005 * 64 * 64));
  // Something dark walks through the middle bracket: a 16x16 block at 10% radiance there.
  cv::Mat moved = L.clone();
  moved(cv::Rect(24, 24, 16, 16)) *= 0.1;
  imgs[2] = testing::synthesize(moved, {e[2]}, cam, 20)[0];
  const MergedImage m = merge_brackets(make_brackets(imgs, e), ResponseCurve::identity(65535), true_noise(cam));
  int flagged_in_block = 0, used_in_block = 0;
  for (int r = 24; r < 40; ++r)
    for (int x = 24; x < 40; ++x) {
      // Only pixels where the middle bracket is unsaturated (else it is excluded anyway).
      if (imgs[2].at<cv::Vec3w>(r, x)[0] >= default_saturation_code(65535)) continue;
      ++used_in_block;
      flagged_in_block += (m.flags.at<unsigned char>(r, x) & kGhost) != 0;
    }
  ASSERT_GT(used_in_block, 100);
  EXPECT_GT(flagged_in_block, int(0.95 * used_in_block));
  // Deghosting: flagged pixels hold one bracket's scene (within 4.5 sigma of its variance channel),
  // not a blend of the two.
  MergeOptions o;
  o.deghost = true;
  const MergedImage d = merge_brackets(make_brackets(imgs, e), ResponseCurve::identity(65535), true_noise(cam), o);
  int blended = 0, checked = 0, blended_plain = 0;
  for (int r = 24; r < 40; ++r)
    for (int x = 24; x < 40; ++x) {
      if (!(d.flags.at<unsigned char>(r, x) & kGhost)) continue;
      ++checked;
      const double v = d.radiance.at<cv::Vec3f>(r, x)[1], a = L.at<cv::Vec3d>(r, x)[1],
                   b = moved.at<cv::Vec3d>(r, x)[1];
      const double sigma = std::sqrt(d.variance.at<cv::Vec3f>(r, x)[1]);
      if (std::abs(v - a) > 4.5 * sigma && std::abs(v - b) > 4.5 * sigma) ++blended;
      const double p = m.radiance.at<cv::Vec3f>(r, x)[1];  // the plain merge, same tolerance
      if (std::abs(p - a) > 4.5 * sigma && std::abs(p - b) > 4.5 * sigma) ++blended_plain;
    }
  ASSERT_GT(checked, 100);
  EXPECT_EQ(blended, 0);
  EXPECT_GT(blended_plain, checked / 2);  // the check can tell a blend
}

TEST(Merge, BeatsHatWeightingByThreeDecibelsInTheDarkestDecade) {
  BracketCamera cam;
  cam.read_sigma = 5e-4;
  const auto e = testing::exposure_series(1.0 / 1000, 4.0, 7);
  const auto levels = log_levels(-3.0, 2.0, 50);  // the darkest decade: levels below 10^-2
  const cv::Mat L = level_scene(levels, 200);
  const BracketSet b = make_brackets(testing::synthesize(L, e, cam, 21), e);
  const MergedImage m = merge_brackets(b, ResponseCurve::identity(65535), true_noise(cam));
  const cv::Mat hat = merge_hat_weighted(b, ResponseCurve::identity(65535));
  double signal = 0, err_ours = 0, err_hat = 0;
  for (int x = 0; x < int(levels.size()); ++x) {
    if (levels[std::size_t(x)] >= 10 * levels[0]) continue;
    for (int r = 0; r < L.rows; ++r)
      for (int c = 0; c < 3; ++c) {
        const double t = L.at<cv::Vec3d>(r, x)[c];
        signal += t * t;
        err_ours += std::pow(m.radiance.at<cv::Vec3f>(r, x)[c] - t, 2);
        err_hat += std::pow(hat.at<cv::Vec3f>(r, x)[c] - t, 2);
      }
  }
  const double snr_ours = 10 * std::log10(signal / err_ours), snr_hat = 10 * std::log10(signal / err_hat);
  EXPECT_GT(snr_ours - snr_hat, 3.0) << "ours " << snr_ours << " dB, hat " << snr_hat << " dB";
}

TEST(Merge, MismatchedCurveIsAnError) {
  const BracketSet b = make_brackets({cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(9))}, {1.0});
  EXPECT_THROW(merge_brackets(b, ResponseCurve::identity(65535), NoiseModel{}), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
