// What response recovery (response_recovery.h), saturation detection (saturation_level.h) and the
// noise estimate (noise_model.h) keep of each view's brackets, gathered one view at a time so that
// a photo set's views never need to be in memory together:
//   - a grid of sample candidates: each pixel's codes in every bracket and the roughness of its
//     5x5 patch in each (the standard deviation of the codes, mean over channels, / max_code);
//   - a denser grid of pixels for the noise estimate: codes and local activity in every bracket
//     (code_activity below: what JPEG's compression error grows with);
//   - per channel, the joint histogram of the codes of bracket pairs (shorter j, longer k) with
//     e_k / e_j >= 1.5 (k the first such), codes binned to 256 levels.
// Grid sizes: about `candidates` and `noise_pixels` over all views together, at least 10000 and
// 20000 per view.
#pragma once

#include "hdr/bracket_set.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace rsibr {

// Local activity of channel c at pixel (r, x) of an RGB code image (CV_16UC3), in codes: the
// largest central-difference gradient magnitude, sqrt(((z_right - z_left) / 2)^2 + ((z_down - z_up) / 2)^2),
// over the pixel's 3x3 neighbourhood (edge pixels repeat the edge): JPEG's error at a pixel comes
// from the busiest content of its block, edges ringing into their neighbours.
inline float code_gradient(const cv::Mat& codes, int r, int x, int c) {
  const int up = std::max(r - 1, 0), down = std::min(r + 1, codes.rows - 1);
  const int left = std::max(x - 1, 0), right = std::min(x + 1, codes.cols - 1);
  const float gx =
      0.5f * (float(codes.ptr<std::uint16_t>(r)[3 * right + c]) - float(codes.ptr<std::uint16_t>(r)[3 * left + c]));
  const float gy =
      0.5f * (float(codes.ptr<std::uint16_t>(down)[3 * x + c]) - float(codes.ptr<std::uint16_t>(up)[3 * x + c]));
  return std::sqrt(gx * gx + gy * gy);
}
inline float code_activity(const cv::Mat& codes, int r, int x, int c) {
  float a = 0;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc)
      a = std::max(
          a, code_gradient(codes, std::clamp(r + dr, 0, codes.rows - 1), std::clamp(x + dc, 0, codes.cols - 1), c));
  return a;
}

struct ViewStatistics {
  std::vector<double> exposures;  // ascending
  int brackets = 0;
  std::vector<std::uint16_t> sample_codes;  // [candidate][bracket][channel]
  std::vector<float> sample_roughness;      // [candidate][bracket]
  std::vector<std::uint16_t> noise_codes;   // [pixel][bracket][channel]
  std::vector<float> noise_activity;        // [pixel][bracket][channel], code_activity

  std::size_t candidates() const { return brackets ? sample_roughness.size() / std::size_t(brackets) : 0; }
  std::size_t noise_pixels() const { return brackets ? noise_codes.size() / (3 * std::size_t(brackets)) : 0; }
  const std::uint16_t* sample(std::size_t i) const { return &sample_codes[i * std::size_t(brackets) * 3]; }
  const std::uint16_t* noise_pixel(std::size_t i) const { return &noise_codes[i * std::size_t(brackets) * 3]; }
  const float* noise_pixel_activity(std::size_t i) const { return &noise_activity[i * std::size_t(brackets) * 3]; }
};

struct BracketStatistics {
  int max_code = 0;
  bool lossy = false;  // some view came from lossy files (BracketSet::lossy)
  int shift = 0;       // histogram bin = code >> shift
  int bins = 0;
  std::vector<ViewStatistics> views;  // views with at least two brackets
  int single_bracket_views = 0;
  std::array<std::vector<long>, 3> pair_histogram;  // per channel, [bin of z_j * bins + bin of z_k]

  // expected_views sizes the grids (candidates and noise_pixels over all views).
  explicit BracketStatistics(int expected_views = 1, int candidates = 80000, int noise_pixels = 200000);
  // Adds one view. Throws std::runtime_error when its bit depth differs from the views before.
  void add(const BracketSet& b);

 private:
  int expected_views_, candidates_, noise_pixels_;
};

}  // namespace rsibr
