// The sRGB transfer function of IEC 61966-2-1, the one place it is written: code value u in [0, 1]
// (an 8-bit code over 255) <-> linear x in [0, 1].
//   decode: x = u / 12.92 for u <= 0.04045, else ((u + 0.055) / 1.055)^2.4
//   encode: u = 12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055
#pragma once

#include <cmath>

namespace rsibr {

inline double srgb_decode(double u) { return u <= 0.04045 ? u / 12.92 : std::pow((u + 0.055) / 1.055, 2.4); }
inline double srgb_encode(double x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055; }

}  // namespace rsibr
