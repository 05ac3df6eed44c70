// Sensor and file noise in the linearised signal X (normalised so that X = 1 at saturation), per
// channel:
//
//   var(X) = shot X + read + (1/12 + code + texture a^2) step(z)^2,   step(z) = X(z + 1/2) - X(z - 1/2)
//
// shot = 1 / (photo-electrons at saturation) (Poisson), read = read-noise variance in X units,
// step^2 / 12 the quantisation of the code (ResponseCurve::tables). code and texture describe what a
// lossy file (JPEG) adds after quantisation, in code units squared: a floor, and a part that grows
// with the local activity a of the image at the pixel (code_activity, bracket_statistics.h), as
// JPEG's error does (the quantised DCT coefficients of a busy block carry more error). Both are 0
// for a lossless file. a step is about the gradient of X, so the texture part is about the same in
// every bracket that sees the pixel: the merge takes it as common to them (merge.h).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/bracket_statistics.h"
#include "hdr/response_curve.h"

#include <array>
#include <string>
#include <vector>

namespace rsibr {

struct NoiseModel {
  std::array<double, 3> shot{1e-4, 1e-4, 1e-4};
  std::array<double, 3> read{1e-6, 1e-6, 1e-6};
  std::array<double, 3> code{0, 0, 0};
  std::array<double, 3> texture{0, 0, 0};
  std::string source = "default";  // "given", "estimated" or "default"
  int views = 0;                   // estimated: how many views it came from
};

// Estimates the model per channel from the brackets of every view (bracket_statistics.h): for a
// pixel seen unsaturated (saturation_level.h's rule, the curve's saturation codes) in adjacent
// brackets j, k, the difference d = X_j/e_j - X_k/e_k has
//   E[d^2] = shot L (1/e_j + 1/e_k) + read (1/e_j^2 + 1/e_k^2) + sum_{b = j, k} (1/12 + code + texture a_b^2) st_b^2 / e_b^2
// (st the code step in X, a the activity), a linear model fitted by iteratively reweighted
// non-negative least squares (weights 1/E[d^2]^2, since var(d^2) = 2 E[d^2]^2 for Gaussian d),
// dropping differences beyond 10 standard deviations of the current model (motion). code and
// texture are fitted for lossy files only; code also needs a curve whose step varies (for a linear
// curve it cannot be told from read). Pairs are selected on the longer bracket (selecting on the
// noisy shorter one truncates its noise), and the shorter one must be four read-noise sigmas clear
// of the black clip. With fewer usable pairs than 100 returns the default model. Throws
// std::invalid_argument when the curve's max_code differs from the brackets'.
NoiseModel estimate_noise(const BracketStatistics& stats, const ResponseCurve& curve);
NoiseModel estimate_noise(const std::vector<const BracketSet*>& views, const ResponseCurve& curve);
// One view, with every channel saturating at `saturation_code`.
NoiseModel estimate_noise(const BracketSet& brackets, const ResponseCurve& curve, int saturation_code);

}  // namespace rsibr
