// Sensor noise in the linearised signal X (normalised so the top code is X = 1), per channel:
//
//   var(X) = shot * X + read + quantisation(z)
//
// shot = 1 / (photo-electrons at saturation) (Poisson), read = read-noise variance in X units,
// quantisation(z) = (X(z+1/2) - X(z-1/2))^2 / 12 from the response curve (ResponseCurve::tables).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/response_curve.h"

#include <array>
#include <string>

namespace rsibr {

struct NoiseModel {
  std::array<double, 3> shot{1e-4, 1e-4, 1e-4};
  std::array<double, 3> read{1e-6, 1e-6, 1e-6};
  std::string source = "default";  // "given", "estimated" or "default"
};

// Estimates shot and read per channel from the brackets themselves: for a pixel seen unsaturated
// in adjacent brackets j, k the difference d = X_j/e_j - X_k/e_k has
//   E[d^2] = shot * L (1/e_j + 1/e_k) + read (1/e_j^2 + 1/e_k^2) + quantisation terms,
// a linear model in (shot, read) fitted by iteratively reweighted least squares (weights
// 1/E[d^2]^2, since var(d^2) = 2 E[d^2]^2 for Gaussian d) with gross outliers (motion) dropped.
// Pairs are selected on the longer bracket (selecting on the noisy shorter one truncates its
// noise), and the shorter one must be four read-noise sigmas clear of the black clip.
// Needs at least two brackets; with fewer usable pairs than 100 returns the default model.
// Throws std::invalid_argument when the curve's max_code differs from the brackets'.
NoiseModel estimate_noise(const BracketSet& brackets, const ResponseCurve& curve, int saturation_code);

}  // namespace rsibr
