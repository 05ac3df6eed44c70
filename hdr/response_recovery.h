// Camera response recovery from a view's brackets with known exposures, and the choice of model
// by held-out error.
//
// Samples: pixels on a regular grid, rejected when their 5x5 patch varies strongly (texture or
// edges make misregistration costly), when their codes decrease with exposure in any channel
// (motion), or when no bracket sees them between near-black and saturation; the rest are binned
// by a log-radiance proxy and each bin keeps its smoothest pixels (balanced across the histogram).
// Selected samples alternate into a training and a held-out half. No random draws: the same
// brackets give the same samples and the same curve, bit for bit.
//
// Models (each fitted per channel on the training half, X(top code) = 1):
//   identity    X = u, u = z / max_code (linear input)
//   gamma       X = u^gamma: gamma * (ln u_j - ln u_k) = ln e_j - ln e_k, least squares, closed form
//   polynomial  X = sum_{n=1..d} c_n u^n, sum c_n = 1 (Mitsunaga & Nayar with known exposure ratios),
//               degree 2..5 chosen by held-out error; rejected unless monotone
//   robertson   Robertson, Borman & Stevenson 1999: alternate L_i = sum w e_j X(z_ij) / sum w e_j^2
//               and X(m) = mean over z_ij = m of L_i e_j, 256 bins, Gaussian-like weights
//   debevec     Debevec & Malik 1997: g = ln X at 256 knots, w(z) (g(z_ij) - ln L_i - ln e_j) = 0 plus
//               lambda w (g'') = 0, solved in double precision with ln L_i eliminated per sample and
//               g monotone (g = T delta, delta >= 0, non-negative least squares)
// Exposures in a constant ratio r leave a curve ambiguous up to a factor periodic in ln X with
// period ln r (every pair of brackets is consistent with it; Grossberg & Nayar 2003): the data
// cannot see it, smoothness (Debevec) or a parametric form removes it. Irregular ratios break it.
// Held-out error: on the held-out samples, each pixel's radiance from its best-exposed bracket
// predicts its codes in the other brackets through the inverse curve; the RMS code error (in
// units of max_code) is the score (a perfect curve leaves only noise). The chosen model is the
// simplest whose held-out error is within 5% of the best (model only what the data supports).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/response_curve.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace rsibr {

// Codes of the selected sample pixels: codes[i][j][c] for sample i, bracket j, channel c.
struct ResponseSamples {
  std::vector<std::vector<std::array<int, 3>>> codes;
  std::vector<bool> held_out;  // per sample
  int max_code = 255;
  int low_code = 12;           // codes below are near-black (max_code / 20; not used for fitting)
  int saturation_code = 254;   // codes at or above are saturated
};

struct RecoveryOptions {
  std::string model = "auto";  // auto, identity, gamma, polynomial, robertson, debevec
  int samples = 3000;          // target number of sample pixels (both halves)
  double smoothness = 100.0;   // Debevec's lambda, relative to the data term per knot
  int saturation_code = -1;    // -1: max_code - max_code / 200
};

struct ModelCandidate {
  std::string model;
  int complexity = 0;              // free parameters per channel
  double held_out_error = 0;       // RMS code error / max_code on the held-out half (inf when rejected)
  nlohmann::json parameters;
};

struct ResponseRecovery {
  ResponseCurve curve;
  std::vector<ModelCandidate> candidates;  // every model tried, in order of complexity
  int train_samples = 0, held_out_samples = 0;
};

int default_saturation_code(int max_code);

// Throws std::runtime_error when too few pixels are usable (all black, all white, one bracket).
ResponseSamples select_samples(const BracketSet& brackets, const RecoveryOptions& options = {});

// Fits one model ("identity", "gamma", "polynomial:<d>", "robertson", "debevec") on the training
// half. Throws std::invalid_argument for an unknown name.
ResponseCurve fit_response(const std::string& model, const ResponseSamples& samples,
                           const std::vector<double>& exposures, const RecoveryOptions& options = {});

// RMS over channels of the held-out log error (see above); +inf when no held-out pixel has two
// usable brackets.
double held_out_error(const ResponseCurve& curve, const ResponseSamples& samples, const std::vector<double>& exposures);

ResponseRecovery recover_response(const BracketSet& brackets, const RecoveryOptions& options = {});

}  // namespace rsibr
