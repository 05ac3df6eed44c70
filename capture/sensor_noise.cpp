#include "capture/sensor_noise.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

double sample_poisson(double mu, NoiseRng& rng) {
  if (!(mu > 0)) return 0;
  if (mu < 10) {
    // Multiplication method: the number of uniforms whose running product stays above e^-mu.
    const double limit = std::exp(-mu);
    double prod = rng.uniform();
    double k = 0;
    while (prod > limit) {
      prod *= rng.uniform();
      k += 1;
    }
    return k;
  }
  // PTRS (Hormann 1993, "The transformed rejection method for generating Poisson random variables").
  const double slam = std::sqrt(mu), loglam = std::log(mu);
  const double b = 0.931 + 2.53 * slam;
  const double a = -0.059 + 0.02483 * b;
  const double invalpha = 1.1239 + 1.1328 / (b - 3.4);
  const double vr = 0.9277 - 3.6224 / (b - 2);
  for (;;) {
    const double u = rng.uniform() - 0.5;
    const double v = rng.uniform();
    const double us = 0.5 - std::abs(u);
    const double k = std::floor((2 * a / us + b) * u + mu + 0.43);
    if (us >= 0.07 && v <= vr) return k;
    if (k < 0 || (us < 0.013 && v > us)) continue;
    if (std::log(v) + std::log(invalpha) - std::log(a / (us * us) + b) <= -mu + k * loglam - std::lgamma(k + 1))
      return k;
  }
}

double sample_normal(NoiseRng& rng) {
  const double u1 = 1.0 - rng.uniform();  // (0, 1]
  const double u2 = rng.uniform();
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * 3.14159265358979323846 * u2);
}

double record_electrons(double mu, const SensorNoise& noise, NoiseRng& rng) {
  // Far above the full well the clip is certain: skip the draws (a sun can be 1e9 electrons).
  if (mu > noise.full_well + 40 * std::sqrt(mu) + 40 * noise.read_noise) return noise.full_well;
  const double x = sample_poisson(mu, rng) + (noise.read_noise > 0 ? noise.read_noise * sample_normal(rng) : 0.0);
  return std::clamp(x, 0.0, noise.full_well);
}

// round(f(x) M) = #{i : f(x) M >= i + 1/2} = #{i : x >= f^-1((i + 1/2) / M)} for an increasing f, so
// the code is the number of thresholds t_i = f^-1((i + 1/2) / M) full_well at or below X: a binary
// search instead of a pow per sample (same codes up to exact ties).
cv::Mat expose_bracket(const cv::Mat& radiance, double e, const SensorNoise& noise, const CameraResponse& response,
                       int max_code, std::uint64_t seed, std::uint64_t stream) {
  const int ch = radiance.channels();
  std::vector<std::vector<double>> thresholds(static_cast<std::size_t>(ch));
  for (int c = 0; c < ch; ++c)
    for (int i = 0; i < max_code; ++i)
      thresholds[std::size_t(c)].push_back(response.relative((i + 0.5) / max_code, ch == 1 ? 1 : c) * noise.full_well);
  cv::Mat out(radiance.rows, radiance.cols, CV_16UC(ch));
  parallel_for_rows(radiance.rows, [&](int y) {
    const float* in = radiance.ptr<float>(y);
    std::uint16_t* o = out.ptr<std::uint16_t>(y);
    for (int x = 0; x < radiance.cols; ++x) {
      NoiseRng rng(seed, (stream << 40) + std::uint64_t(y) * std::uint64_t(radiance.cols) + std::uint64_t(x));
      for (int c = 0; c < ch; ++c) {
        const double mu = std::max(0.0, double(in[x * ch + c])) * e * noise.gain;
        const double X = record_electrons(mu, noise, rng);
        const auto& t = thresholds[std::size_t(c)];
        o[x * ch + c] = std::uint16_t(std::upper_bound(t.begin(), t.end(), X) - t.begin());
      }
    }
  });
  return out;
}

cv::Mat expose_raw(const cv::Mat& radiance, double e, const SensorNoise& noise, const Vec3& sensitivity,
                   std::uint64_t seed, std::uint64_t stream) {
  if (radiance.type() != CV_32FC3) throw std::invalid_argument("expose_raw: radiance must be CV_32FC3");
  cv::Mat out(radiance.rows, radiance.cols, CV_64FC3);
  parallel_for_rows(radiance.rows, [&](int y) {
    const float* in = radiance.ptr<float>(y);
    double* o = out.ptr<double>(y);
    for (int x = 0; x < radiance.cols; ++x) {
      NoiseRng rng(seed, (stream << 40) + std::uint64_t(y) * std::uint64_t(radiance.cols) + std::uint64_t(x));
      for (int c = 0; c < 3; ++c) {
        const double mu = std::max(0.0, double(in[x * 3 + c])) * e * noise.gain * sensitivity[c];
        o[x * 3 + c] = record_electrons(mu, noise, rng) / noise.full_well;
      }
    }
  });
  return out;
}

}  // namespace rsibr
