// Camera response curves: how a sensor's relative exposure x = X / full_well in [0,1] (X in
// electrons after clipping at the full well) becomes a normalised pixel code f(x) in [0,1], per
// channel (codes are round(f(x) * max_code) for 8 or 16 bits). Every curve is strictly increasing
// with f(0) = 0 and f(1) = 1, so it is invertible; hdr/ recovers it from the brackets and its tests
// compare against table() written into the truth folder.
//
//   linear    f(x) = x
//   srgb      the sRGB transfer function (IEC 61966-2-1): 12.92 x below 0.0031308, else
//             1.055 x^(1/2.4) - 0.055
//   measured  a film-like curve with a toe and a shoulder, different per channel, in the shape of
//             the curves of the DoRF database (Grossberg & Nayar): the Naka-Rushton form
//               f(x) = (1 + a) x^g / (x^g + a)
//             with (g, a) = (0.62, 0.35), (0.58, 0.30), (0.66, 0.42) for R, G, B.
//             Inverse: x = (a f / (1 + a - f))^(1/g).
//   filmic    a consumer camera's JPEG tone curve, the same for every channel: the sRGB encoding
//             u = srgb(x) followed by a contrast S-curve in the encoded domain,
//               f = (1 - w) u + w S(u),  S(u) = u^a / (u^a + (1 - u)^a),  w = 0.5, a = 1.6
//             (slope at both ends half the sRGB one: a toe that deepens the shadows and a
//             highlight shoulder that rolls off toward white; 18% grey -> 0.45, code 115 of 255).
//             Inverse: S is inverted by bisection (f is increasing), then the sRGB decoding.
#pragma once

#include <string>
#include <vector>

namespace rsibr {

class CameraResponse {
 public:
  // "linear", "srgb", "measured" or "filmic"; throws std::invalid_argument otherwise.
  explicit CameraResponse(const std::string& kind = "srgb");
  static const std::vector<std::string>& kinds();

  const std::string& kind() const { return kind_; }
  // f_c(x), x clamped to [0,1]; channel c in {0,1,2} (R, G, B).
  double code(double x, int c) const;
  // The inverse: relative exposure of a normalised code in [0,1].
  double relative(double f, int c) const;
  // One row per code 0..max_code: relative exposure of that code's centre per channel
  // (relative(code / max_code)); row i = {i, x_R, x_G, x_B}.
  std::vector<std::vector<double>> table(int max_code) const;

 private:
  std::string kind_;
};

}  // namespace rsibr
