// Bilinear sampling of one sphere map inside its disc, in double: the definition of a blend tap.
// The blend engine (runtime/blend_engine.h) computes the same in float from its own layout and
// falls back to this where none of a footprint's taps is valid; the renderer reads its destination
// maps with it; the tests' oracle (tests/runtime/blend_oracle.h) uses it throughout.
//
// Contract: xy are disc coordinates (x right, y up; core/sphere_map.h) of a width x height map. The
// four bilinear taps around xy's continuous pixel position are clamped to the image; taps whose
// centres lie outside the unit disc (x^2 + y^2 > 1, the test core's sphere-map sampling uses) are
// dropped and the rest renormalised. When every tap is outside, xy is stepped toward the centre by
// a factor (1 - 1/max(W, H)), at most 8 times; then the sample fails (not expected for maps of
// 2 x 2 or more).
#pragma once

#include "core/sphere_map.h"
#include "core/vec.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

namespace rsibr {

struct DiscMap {
  const cv::Mat* rgb = nullptr;         // CV_32FC3, RGB
  const cv::Mat* confidence = nullptr;  // nullptr, or CV_32FC1 of the same size
  int width = 0, height = 0;
};

// Writes the RGB sample and the confidence (bilinear in the confidence channel, negative or NaN
// counted as 0; 1 without a channel). Returns false when no tap is valid (outputs untouched).
inline bool sample_disc(const DiscMap& s, Vec2 xy, double rgb[3], double* confidence) {
  const int W = s.width, H = s.height;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const Vec2 p = sphere_map::pixel_from_disc(xy, W, H);
    const double fc = std::floor(p.x()), fr = std::floor(p.y());
    const double fx = p.x() - fc, fy = p.y() - fr;
    const int c0 = int(fc), r0 = int(fr);
    const int cs[2] = {std::clamp(c0, 0, W - 1), std::clamp(c0 + 1, 0, W - 1)};
    const int rs[2] = {std::clamp(r0, 0, H - 1), std::clamp(r0 + 1, 0, H - 1)};
    const double wx[2] = {1 - fx, fx}, wy[2] = {1 - fy, fy};
    double acc[3] = {0, 0, 0}, conf = 0, total = 0;
    for (int j = 0; j < 2; ++j) {
      const double y = 1.0 - (2.0 * rs[j] + 1.0) / H;
      const float* row = s.rgb->ptr<float>(rs[j]);
      const float* crow = s.confidence ? s.confidence->ptr<float>(rs[j]) : nullptr;
      for (int i = 0; i < 2; ++i) {
        const double w = wx[i] * wy[j];
        if (!(w > 0)) continue;
        const double x = (2.0 * cs[i] + 1.0) / W - 1.0;
        if (x * x + y * y > 1.0) continue;
        const float* t = row + 3 * cs[i];
        acc[0] += w * t[0];
        acc[1] += w * t[1];
        acc[2] += w * t[2];
        if (crow) conf += w * crow[cs[i]];
        total += w;
      }
    }
    if (total > 0) {
      const double inv = 1.0 / total;
      rgb[0] = acc[0] * inv;
      rgb[1] = acc[1] * inv;
      rgb[2] = acc[2] * inv;
      // A confidence is a weight: negative or NaN counts as 0.
      const double c = s.confidence ? conf * inv : 1.0;
      *confidence = c > 0 ? c : 0.0;
      return true;
    }
    xy *= 1.0 - 1.0 / std::max(W, H);  // every tap outside the disc: step inward
  }
  return false;
}

}  // namespace rsibr
