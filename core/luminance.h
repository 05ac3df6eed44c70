// Luminance of working-space linear RGB: Y = w . rgb with the OCIO config's luma coefficients
// (core/colour.h: $OCIO's config, or the built-in one, whose working space is linear Rec.709 and
// whose coefficients are Rec.709's 0.2126 0.7152 0.0722). Read once per process. Every stage
// that weighs colours by brightness (importance sampling, bright-texel clusters, ball finding,
// previews, gain fits) uses this one rule, so a config with another working space (ACEScg) keeps
// them consistent.
#pragma once

#include <array>
#include <cmath>

namespace rsibr {

// The config's coefficients (positive, summing to 1 within rounding); Rec.709's when the config
// gives none.
const std::array<double, 3>& luma_coefficients();

// Y of an RGB triple (anything indexable by 0..2).
template <class RGB>
double luminance(const RGB& rgb) {
  const std::array<double, 3>& w = luma_coefficients();
  return w[0] * double(rgb[0]) + w[1] * double(rgb[1]) + w[2] * double(rgb[2]);
}

// Y with non-finite and negative channels counted as 0 (radiance that cannot be negative).
template <class RGB>
double positive_luminance(const RGB& rgb) {
  auto pos = [](double v) { return std::isfinite(v) && v > 0 ? v : 0.0; };
  const std::array<double, 3>& w = luma_coefficients();
  return w[0] * pos(double(rgb[0])) + w[1] * pos(double(rgb[1])) + w[2] * pos(double(rgb[2]));
}

}  // namespace rsibr
