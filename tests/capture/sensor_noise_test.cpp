// capture/sensor_noise.h: the noise model's statistics (Poisson shot noise plus Gaussian read noise,
// clipped at the full well) and its determinism.
#include "capture/sensor_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rsibr {
namespace {

struct Moments {
  double mean = 0, var = 0;
};

Moments moments(const std::vector<double>& x) {
  Moments m;
  for (double v : x) m.mean += v;
  m.mean /= double(x.size());
  for (double v : x) m.var += (v - m.mean) * (v - m.mean);
  m.var /= double(x.size() - 1);
  return m;
}

// Mean within 5 standard errors of mu and variance within 5 standard errors of sigma^2 (the
// variance of a sample variance is about 2 sigma^4 / n for near-normal data, plus the Poisson
// excess kurtosis mu for small mu).
void expect_moments(const std::vector<double>& x, double mu, double var, const std::string& what) {
  const double n = double(x.size());
  const Moments m = moments(x);
  EXPECT_NEAR(m.mean, mu, 5 * std::sqrt(var / n)) << what;
  const double var_se = std::sqrt((2 * var * var + mu) / n);
  EXPECT_NEAR(m.var, var, 5 * var_se) << what;
}

TEST(SensorNoise, PoissonHasMeanAndVarianceMuAtEveryScale) {
  for (double mu : {0.3, 3.5, 9.9, 10.0, 47.0, 1e3, 1e5}) {
    std::vector<double> x;
    for (int i = 0; i < 40000; ++i) {
      NoiseRng rng(11, std::uint64_t(i));
      x.push_back(sample_poisson(mu, rng));
    }
    expect_moments(x, mu, mu, "mu = " + std::to_string(mu));
    for (double v : x) ASSERT_EQ(v, std::floor(v));
  }
}

TEST(SensorNoise, PoissonProbabilitiesMatchThePmf) {
  // Chi-square over k = 0..14 (the rest pooled) at mu = 4 and mu = 12 (both samplers).
  for (double mu : {4.0, 12.0}) {
    const int n = 100000, bins = 25;
    std::vector<double> count(bins + 1, 0);
    for (int i = 0; i < n; ++i) {
      NoiseRng rng(5, std::uint64_t(i));
      const int k = int(sample_poisson(mu, rng));
      count[std::size_t(std::min(k, bins))] += 1;
    }
    double chi2 = 0, tail = 1;
    for (int k = 0; k <= bins; ++k) {
      const double p = k < bins ? std::exp(-mu + k * std::log(mu) - std::lgamma(k + 1.0)) : tail;
      tail -= k < bins ? p : 0;
      if (n * p < 5) continue;
      chi2 += (count[std::size_t(k)] - n * p) * (count[std::size_t(k)] - n * p) / (n * p);
    }
    EXPECT_LT(chi2, 60.0) << "mu = " << mu;  // < 26 degrees of freedom; p ~ 1e-4 bound
  }
}

TEST(SensorNoise, RecordedElectronsHaveShotPlusReadVariance) {
  const SensorNoise noise{1.0, 1e6, 4.0};
  for (double mu : {0.0, 20.0, 5000.0}) {
    std::vector<double> x;
    for (int i = 0; i < 40000; ++i) {
      NoiseRng rng(3, std::uint64_t(i));
      x.push_back(record_electrons(mu, noise, rng));
    }
    if (mu > 100) expect_moments(x, mu, mu + 16, "mu = " + std::to_string(mu));
    for (double v : x) EXPECT_GE(v, 0);  // clipped at zero
  }
}

TEST(SensorNoise, BracketCodesFollowTheModelAndClipAtFullWell) {
  // Linear response, 16-bit codes and a full well of 65535 electrons: a code is an electron count.
  const SensorNoise noise{2.0, 65535, 3.0};
  const CameraResponse linear("linear");
  cv::Mat L(100, 100, CV_32FC3, cv::Scalar(1000, 40, 1e9));  // mu = L * e * k with e = 0.5, k = 2
  const cv::Mat codes = expose_bracket(L, 0.5, noise, linear, 65535, 9, 1);
  std::vector<double> r, g;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) {
      const cv::Vec3w c = codes.at<cv::Vec3w>(y, x);
      r.push_back(c[0]);
      g.push_back(c[1]);
      EXPECT_EQ(c[2], 65535);  // far beyond the full well: clipped
    }
  // Rounding to integer codes adds 1/12 to the variance of the continuous read noise.
  expect_moments(r, 1000, 1000 + 9 + 1.0 / 12, "R");
  expect_moments(g, 40, 40 + 9 + 1.0 / 12, "G");
}

TEST(SensorNoise, BracketCodesAreTheRoundedResponseOfTheRecordedElectrons) {
  // The binary search over response thresholds gives round(f(X / full_well) * max_code), X drawn
  // from the documented stream of each pixel.
  const SensorNoise noise{3.0, 2e4, 2.5};
  for (const std::string kind : {"srgb", "measured"}) {
    const CameraResponse response(kind);
    cv::Mat L(30, 40, CV_32FC3);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x) L.at<cv::Vec3f>(y, x) = cv::Vec3f(float(x * x * 5), float(y * 30 + 1), float(x * y));
    for (int max_code : {255, 65535}) {
      const cv::Mat codes = expose_bracket(L, 2.0, noise, response, max_code, 4, 6);
      int mismatched = 0;
      for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 40; ++x) {
          NoiseRng rng(4, (std::uint64_t(6) << 40) + std::uint64_t(y * 40 + x));
          for (int c = 0; c < 3; ++c) {
            const double X = record_electrons(L.at<cv::Vec3f>(y, x)[c] * 2.0 * 3.0, noise, rng);
            const long want = std::lround(response.code(X / noise.full_well, c) * max_code);
            mismatched += codes.ptr<std::uint16_t>(y)[3 * x + c] != want;
          }
        }
      EXPECT_EQ(mismatched, 0) << kind << " " << max_code;
    }
  }
}

TEST(SensorNoise, SameSeedAndStreamGiveSameCodesOtherwiseDifferent) {
  const SensorNoise noise{5.0, 2e4, 3.0};
  const CameraResponse srgb("srgb");
  cv::Mat L(40, 50, CV_32FC3, cv::Scalar(100, 200, 300));
  const cv::Mat a = expose_bracket(L, 1, noise, srgb, 255, 1, 2), b = expose_bracket(L, 1, noise, srgb, 255, 1, 2);
  const cv::Mat c = expose_bracket(L, 1, noise, srgb, 255, 1, 3), d = expose_bracket(L, 1, noise, srgb, 255, 2, 2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, d, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace rsibr
