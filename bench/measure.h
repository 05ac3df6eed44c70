// Helpers shared by the measurement tools of bench/ (bake_tradeoff, runtime_tradeoff, multi_lobe):
// CC0 environments as rsibr's --sanitize reads them, fixed random probe texels, pooled errors.
#pragma once

#include "formats/exr_io.h"
#include "core/sphere_map.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

namespace rsibr::bench {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The file with NaN, Inf and negative values zeroed (DWAB ringing of the CC0 maps; docs/conventions.md).
inline EnvMap load_sanitized(const std::string& path) {
  EnvMap env = read_environment(path);
  const int ch = env.channels();
  for (int r = 0; r < env.pixels.rows; ++r) {
    float* row = env.pixels.ptr<float>(r);
    for (int i = 0; i < env.pixels.cols * ch; ++i)
      if (!std::isfinite(row[i]) || row[i] < 0) row[i] = 0.f;  // DWAB ringing (docs/conventions.md)
  }
  return env;
}

inline  // `count` distinct random texels whose centres lie inside the disc (radius^2 < 0.98), fixed by the seed.
    cv::Mat
    probe_mask(int size, int count, std::uint32_t seed) {
  cv::Mat mask(size, size, CV_8UC1, cv::Scalar(0));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, size - 1);
  int placed = 0;
  while (placed < count) {
    const int c = pick(rng), r = pick(rng);
    if (!(sphere_map::disc_from_pixel(Vec2(c, r), size, size).squaredNorm() < 0.98)) continue;
    if (mask.at<unsigned char>(r, c)) continue;
    mask.at<unsigned char>(r, c) = 1;
    ++placed;
  }
  return mask;
}

// Pooled error sums over masked texels or pixels.
struct ErrorSums {
  double num = 0, den = 0, worst_abs = 0;
  long count = 0;
  // a, ref: CV_32FC3 or CV_32FC4 (the first three channels are compared); mask: CV_8UC1.
  void add(const cv::Mat& a, const cv::Mat& ref, const cv::Mat& mask, cv::Mat* abs_error = nullptr) {
    const int ca = a.channels(), cr = ref.channels();
    if (abs_error) *abs_error = cv::Mat(a.rows, a.cols, CV_32FC1, cv::Scalar(0));
    for (int r = 0; r < a.rows; ++r) {
      const float* pa = a.ptr<float>(r);
      const float* pr = ref.ptr<float>(r);
      for (int c = 0; c < a.cols; ++c) {
        if (!mask.at<unsigned char>(r, c)) continue;
        double e2 = 0, y2 = 0;
        for (int k = 0; k < 3; ++k) {
          const double x = pa[c * ca + k], y = pr[c * cr + k];
          e2 += (x - y) * (x - y);
          y2 += y * y;
        }
        num += e2;
        den += y2;
        worst_abs = std::max(worst_abs, std::sqrt(e2));
        ++count;
        if (abs_error) abs_error->at<float>(r, c) = float(std::sqrt(e2));
      }
    }
  }
  double relative_rms() const { return den > 0 ? std::sqrt(num / den) : 0.0; }
  // The worst texel's error in units of the reference's RMS radiance (|rgb|_2) over the same texels.
  double worst() const { return den > 0 ? worst_abs / std::sqrt(den / double(count)) : 0.0; }
};

}  // namespace rsibr::bench
