// Camera response recovery from the brackets of every view with known exposures, and the choice
// of model by held-out error.
//
// Saturation (saturation_level.h): measured per channel from the data unless given; a bracket
// saturated in any channel at a pixel is not used for any channel there, nor is any longer one.
//
// Samples, from every view (bracket_statistics.h): pixels on a regular grid, rejected when their
// 5x5 patch varies strongly (texture or edges make misregistration and JPEG ringing costly), when
// their codes decrease with exposure in any channel (motion, compression), or when fewer than two
// brackets see them between black and saturation; the rest are stratified over code and exposure:
// binned by a log-radiance proxy (the best-exposed bracket's mean code over its exposure,
// comparable across views), each bin keeping its smoothest pixels taken from the views in turn
// (bins with few candidates give all and leave their share to the others). Selected samples
// alternate into two halves. A first shared Debevec curve then removes what it cannot explain
// (clean_samples: saturated signal below the saturation code, moving pixels). No random draws: the
// same brackets give the same samples and the same curve, bit for bit.
//
// Models, each fitted on the training half either per channel or shared by the three channels
// (one curve: in-camera processing applies one tone curve to every channel after its colour
// matrix, which a per-channel fit can only approximate with more parameters):
//   identity    X = u, u = z / max_code (linear input)
//   gamma       X = u^gamma: gamma * (ln u_j - ln u_k) = ln e_j - ln e_k, least squares, closed form
//   polynomial  X = sum_{n=1..d} c_n u^n, sum c_n = 1 (Mitsunaga & Nayar with known exposure ratios),
//               degree 2..5; rejected unless monotone
//   debevec     Debevec & Malik 1997: g = ln X at 256 knots, w(z) (g(z_ij) - ln L_i - ln e_j) = 0 plus
//               lambda w (g'') = 0 (g'' in log code toward black), solved in double precision with
//               ln L_i eliminated per sample and g monotone (g = T delta, delta >= 0, non-negative
//               least squares); lambda 10x and 1x `smoothness`, the smoother tried first
//   robertson   Robertson, Borman & Stevenson 1999: alternate L_i = sum w e_j X(z_ij) / sum w e_j^2
//               and X(m) = mean over z_ij = m of L_i e_j, 256 bins, Gaussian-like weights; each X
//               update is smoothed in ln X by the same penalty as Debevec's (only when asked for)
// Gamma and polynomial leave out the codes below max_code / 20 (their unweighted rows would be led
// by the near-black codes' noise); gamma's rows are weighted by 1 / var(ln z_j - ln z_k).
// Exposures in a constant ratio r leave a curve ambiguous up to a factor periodic in ln X with
// period ln r (every pair of brackets is consistent with it; Grossberg & Nayar 2003): the data
// cannot see it; smoothness (part of the debevec and robertson models) or a parametric form removes
// it. Irregular ratios break it.
//
// Channels are tied where every model is best constrained, the middle code: X_c(max_code / 2) is
// the same for every channel, so equal mid-grey codes stay neutral (the camera's own white balance,
// as the camera rendered it). Above a channel's saturation code the curve is flat (no data there:
// a clipped value X(saturation) / e is then a lower bound). Then one factor for all channels puts
// the largest top knot at 1.
//
// Held-out error: each half fitted, the other scored (two-fold); each scored pixel's radiance from
// its best-exposed bracket predicts its codes in the other brackets through the inverse curve; the
// RMS code error (in units of max_code; codes from max_code / 20 up; Huber's loss beyond 3 sigma of
// the residuals) is the score (a perfect curve leaves only noise).
// Choice: first the channels: one shared curve unless the best per-channel curve's mean squared
// error is below 1 / 1.5 of the best shared one's, judged on the samples the camera rendered grey
// when there are 200 of them (elsewhere JPEG's chroma errors favour per-channel curves without
// making them truer); then, among those, the best model unless a simpler one (in this order:
// identity, gamma, Debevec smoother first, then polynomials by degree) is within the held-out noise
// of it: its excess mean squared error below tie_sigmas standard errors of the per-sample paired
// difference plus tie_relative of the best's. The margin is how far the decisions are from their
// thresholds, in standard errors; under one it is a near tie (warning).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/bracket_statistics.h"
#include "hdr/response_curve.h"
#include "hdr/saturation_level.h"

#include <nlohmann/json.hpp>

#include <array>
#include <string>
#include <vector>

namespace rsibr {

// Codes of the selected sample pixels: codes[i][j][c] for sample i, bracket j of its view, channel c.
struct ResponseSamples {
  std::vector<std::vector<std::array<int, 3>>> codes;
  std::vector<int> view;                       // per sample: its view (index into exposures)
  std::vector<int> saturated_from;             // per sample: brackets from this one on are saturated
  std::vector<std::vector<double>> exposures;  // per view, ascending
  std::vector<bool> held_out;                  // per sample
  int max_code = 255;
  int low_code = 2;                              // codes below are black (max(2, max_code / 128)); the parametric
                                                 // fits also leave out those below max_code / 20
  std::array<int, 3> saturation{254, 254, 254};  // per channel: codes at or above are saturated
};

struct RecoveryOptions {
  std::string model = "auto";     // auto, identity, gamma, polynomial, robertson, debevec
  std::string channels = "auto";  // auto (both, by held-out error), shared, separate
  int samples = 20000;            // target number of sample pixels (both halves, all views)
  double smoothness = 1000.0;     // lambda of debevec and robertson, relative to the data term per knot
                                  // (auto tries debevec at 10x and 1x it)
  std::array<int, 3> saturation_code{-1, -1, -1};  // per channel; -1: measured (saturation_level.h)
  double tie_sigmas = 2.0;                         // a simpler model within this many standard errors of the best wins
  double tie_relative = 0.03;                      // ... or within this fraction of the best's mean squared error
};

struct ModelCandidate {
  std::string model;          // family: identity, gamma, polynomial, robertson, debevec
  bool shared = false;        // one curve for the three channels
  int complexity = 0;         // free parameters (all channels); the tie-break order
  double held_out_error = 0;  // RMS code error / max_code on the held-out half (inf when rejected)
  double excess_sigmas = 0;   // (its MSE - the best's) / standard error of the paired difference
  bool tied = false;          // within the held-out noise of the best
  nlohmann::json parameters;
};

struct ResponseRecovery {
  ResponseCurve curve;
  std::vector<ModelCandidate> candidates;  // every model tried, in order of complexity
  int train_samples = 0, held_out_samples = 0, views = 0;
  long removed_observations = 0;  // brackets found saturated below the code, and moving pixels
  std::string chosen;             // "debevec (shared)", "gamma (per channel)", ...
  double margin_sigmas = 0;       // distance of the choice from the tie threshold (inf: no rival)
  bool near_tie = false;          // margin under one standard error: another shoot may choose otherwise
  std::string warning;            // empty, or what the near tie is between
  SaturationLevel saturation;
};

// Throws std::runtime_error when too few pixels are usable (all black, all white, one bracket).
ResponseSamples select_samples(const BracketStatistics& stats, const std::array<int, 3>& saturation,
                               const RecoveryOptions& options = {});

// Fits one model ("identity", "gamma", "polynomial:<d>", "robertson", "debevec") on the training
// half, per channel or shared, tied and normalised as above. Throws std::invalid_argument for an
// unknown name.
ResponseCurve fit_response(const std::string& model, bool shared, const ResponseSamples& samples,
                           const RecoveryOptions& options = {});

// RMS over channels and held-out observations of the code error (see above); +inf when no held-out
// pixel has two usable brackets.
double held_out_error(const ResponseCurve& curve, const ResponseSamples& samples);

ResponseRecovery recover_response(const BracketStatistics& stats, const RecoveryOptions& options = {});
ResponseRecovery recover_response(const std::vector<const BracketSet*>& views, const RecoveryOptions& options = {});
ResponseRecovery recover_response(const BracketSet& brackets, const RecoveryOptions& options = {});

// The recovery as JSON for summaries and reports: chosen, margin_sigmas, near_tie, warning,
// saturation, samples and the candidates (held-out error "rejected" when not finite).
nlohmann::json recovery_json(const ResponseRecovery& r);

}  // namespace rsibr
