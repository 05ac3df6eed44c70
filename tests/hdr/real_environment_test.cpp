// End to end on real data: brackets synthesized from a CC0 environment with a sun (esplanade),
// through response recovery (model by held-out error), noise estimation and the merge.
#include "hdr/bracket_synth.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"

#include "formats/exr_io.h"
#include "core/test_data.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace rsibr {
namespace {

double luminance(const cv::Vec3d& v) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; }

TEST(RealEnvironment, SunIsFlaggedAsALowerBoundAndMidTonesAreWithinFivePercent) {
  const auto path = testing::assets_dir() / "hdri" / "esplanade.exr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << testing::kNoAssets;
  EnvMap env = read_environment(path.string());
  cv::Mat truth;
  cv::resize(env.pixels, truth, cv::Size(384, 192), 0, 0, cv::INTER_AREA);
  truth.convertTo(truth, CV_64FC3);
  truth.forEach<cv::Vec3d>([](cv::Vec3d& p, const int*) {
    for (int c = 0; c < 3; ++c) p[c] = std::isfinite(p[c]) && p[c] > 0 ? p[c] : 0.0;  // DWAB ringing
  });
  std::vector<double> lum;
  double brightest = 0;
  cv::Point sun;
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x) {
      const double l = luminance(truth.at<cv::Vec3d>(r, x));
      lum.push_back(l);
      if (l > brightest) brightest = l, sun = {x, r};
    }
  std::nth_element(lum.begin(), lum.begin() + long(lum.size() / 2), lum.end());
  const double median = lum[lum.size() / 2];
  const auto e = testing::exposure_series(0.18 / median / 64, 4.0, 7);
  testing::BracketCamera cam;
  cam.max_code = 255;
  cam.response = testing::s_curve;
  const BracketSet b = make_brackets(testing::synthesize(truth, e, cam, 40), e);
  ASSERT_GT(brightest * e[0], 1.0) << "the sun must saturate even the shortest bracket for this test";

  const ResponseRecovery rec = recover_response(b);
  const MergedImage m = merge_brackets(b, rec.curve, estimate_noise({&b}, rec.curve));
  ASSERT_TRUE(cv::checkRange(m.radiance) && cv::checkRange(m.variance));
  EXPECT_TRUE(m.flags.at<unsigned char>(sun) & kClipped);
  // The merge keeps the camera's own white balance (response_curve.h tie_channels): this camera's
  // curves differ per channel, so its equal middle codes are not the truth's grey. The truth in the
  // camera's balance: each channel times the factor the convention gives the true curves.
  ResponseCurve true_curve = ResponseCurve::sampled("true", 255, 256, [&](int c, double u) {
    double lo = 0, hi = 1;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (cam.response(c, mid) < u ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  });
  const ResponseCurve untied = true_curve;
  tie_channels(true_curve);
  cv::Vec3d balance;
  for (int c = 0; c < 3; ++c)
    balance[c] = true_curve.knots[std::size_t(c)].back() / untied.knots[std::size_t(c)].back();
  truth.forEach<cv::Vec3d>([&](cv::Vec3d& p, const int*) {
    for (int c = 0; c < 3; ++c) p[c] *= balance[c];
  });

  // The global factor (the unit is the saturation signal of the channel with the most headroom):
  // median ratio over mid-tones.
  std::vector<double> ratios;
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x) {
      const double l = luminance(truth.at<cv::Vec3d>(r, x));
      if (l > 0.3 * median && l < 3 * median)
        ratios.push_back(l / luminance(cv::Vec3d(m.radiance.at<cv::Vec3f>(r, x))));
    }
  std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
  const double scale = ratios[ratios.size() / 2];
  EXPECT_NEAR(scale, 1.0, 0.1);

  double se = 0;
  long n = 0, clipped = 0;
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x) {
      const cv::Vec3d t = truth.at<cv::Vec3d>(r, x);
      const cv::Vec3f v = m.radiance.at<cv::Vec3f>(r, x);
      if (m.flags.at<unsigned char>(r, x) & kClipped) {
        ++clipped;
        for (int c = 0; c < 3; ++c)
          EXPECT_LE(v[c] * scale, t[c] * 1.05) << "clipped pixel exceeds the truth at " << x << "," << r;
        continue;
      }
      const double l = luminance(t);
      if (l > 0.3 * median && l < 3 * median)
        for (int c = 0; c < 3; ++c) se += std::pow((v[c] * scale - t[c]) / l, 2), ++n;
    }
  EXPECT_GT(clipped, 0);
  EXPECT_LT(std::sqrt(se / double(n)), 0.05);
}

}  // namespace
}  // namespace rsibr
