// A lat-long environment prepared for area-weighted sampling at any latitude: level j holds every
// row box-filtered in longitude to W_j = ceil((W-1) / 2^j) + 1 columns (exact overlaps of the
// texels' longitude intervals, so each row's integral is kept), with the rows unchanged.
//
// Why: a lat-long texel at latitude phi is cos(phi) times narrower than it is tall, so a footprint
// of fixed angular size near a pole spans many columns of level 0; at the level whose texels are
// about square there (level_for_latitude) a few bilinear taps cover it. Memory: about one more
// copy of the map.
#pragma once

#include "core/env_map.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace rsibr {

class LatLongRipmap {
 public:
  // src: lat-long, CV_32F (level 0 is shared with it, not copied).
  explicit LatLongRipmap(const EnvMap& src);

  int levels() const { return int(levels_.size()); }
  const cv::Mat& level(int j) const { return levels_.at(std::size_t(j)); }
  int width(int j) const { return levels_[std::size_t(j)].cols; }
  int height() const { return levels_.front().rows; }
  double inverse_scale(int j) const { return inverse_scale_[std::size_t(j)]; }  // level-j per level-0 columns
  double latitude_step() const;                                                 // radians between rows
  double longitude_step(int j) const;                                           // radians between columns of level j

  // The coarsest level whose texels at latitude phi (radians) are no wider than they are tall.
  int level_for_latitude(double phi) const;

  // Bilinear RGB(...) of level j at a level-0 pixel position (x may lie outside [0, W-1]: it wraps
  // around the seam; y is clamped to the poles). Writes channels() floats.
  void bilinear(int j, double x0, double y, float* out) const;

 private:
  std::vector<cv::Mat> levels_;
  std::vector<double> inverse_scale_;  // level-j columns per level-0 column
};

// Inline: the resampler's inner loop calls it for every tap.
inline void LatLongRipmap::bilinear(int j, double x0, double y, float* out) const {
  const cv::Mat& m = levels_[std::size_t(j)];
  const int w = m.cols, h = m.rows, ch = m.channels();
  // Columns 0 and w - 1 are the same longitude (the seam): positions beyond either wrap by w - 1.
  double x = x0 * inverse_scale_[std::size_t(j)];
  const double period = w - 1;
  if (x < 0 || x > period) x -= period * std::floor(x / period);
  x = std::clamp(x, 0.0, period);
  y = std::clamp(y, 0.0, double(h - 1));
  // The weights and order of sample_bilinear (core/env_map.h), so that level 0 gives its bits.
  const int c0 = std::min(int(x), w - 2), r0 = std::min(int(y), h - 2);
  const float fx = float(x - c0), fy = float(y - r0);
  const float weights[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const float* texels[4] = {m.ptr<float>(r0) + std::size_t(c0) * ch, m.ptr<float>(r0) + std::size_t(c0 + 1) * ch,
                            m.ptr<float>(r0 + 1) + std::size_t(c0) * ch,
                            m.ptr<float>(r0 + 1) + std::size_t(c0 + 1) * ch};
  for (int k = 0; k < ch; ++k) out[k] = 0.f;
  for (int i = 0; i < 4; ++i) {
    if (weights[i] == 0.f) continue;
    for (int k = 0; k < ch; ++k) out[k] += weights[i] * texels[i][k];
  }
}

}  // namespace rsibr
