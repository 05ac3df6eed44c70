// Noise-optimal merge of a view's brackets into radiance.
//
// Per pixel and channel, bracket j gives L_j = X(z_j) / e_j with
//   var(L_j) = (shot * L e_j + read + (1/12 + code) step(z_j)^2) / e_j^2      (noise_model.h)
// and the minimum-variance unbiased combination of independent estimates is
//   L = sum_j w_j L_j / sum_j w_j,  w_j = 1 / var(L_j),  var(L) = 1 / sum_j w_j.
// Evaluating var(L_j) at the measured X_j would favour samples that came out low (a downward
// bias of the shot term), so the weights use a pilot estimate: pass 1 weights with X_j, pass 2
// with L_pilot * e_j (Granados et al. 2010, "Optimal HDR reconstruction with linear digital
// cameras").
//
// Saturation (saturation_level.h, the curve's per-channel saturation codes): a bracket saturated
// in any channel is excluded for that pixel in every channel (a clipped channel drags hue: pink
// suns), and so is every longer bracket (more exposure cannot unsaturate a pixel). Near the top
// (a code within max_code / 8 of its channel's saturation code) a bracket is also treated as
// saturated when it reads significantly less than the shorter usable brackets say it should
// (L_j below their inverse-variance mean by more than 4 standard deviations of the difference, in
// any channel): saturated signal that JPEG ringing and chroma smearing pushed below the saturation
// code. A pixel saturated in every bracket is flagged `clipped`; its value is the shortest
// bracket's X / e_0 (the curve is flat from the saturation code up, so that is at most
// X(saturation) / e_0), a lower bound for the saturated channels, never an extrapolation. A pixel whose longest bracket recorded code 0 in every channel
// is flagged `black` (radiance below what the set can detect; the value is the merge of zeros).
// Ghosts: with L the merge, chi2 = sum_{j,c} (L_j - L)^2 / (var(L_j) + (model_error * L)^2) over the
// used brackets; the channels' residuals are correlated (a JPEG's luma error, a colour matrix's
// shot noise reach all three), so chi2 / 3 is taken as one measurement with n - 1 degrees of freedom
// for a static scene (under independence it is only tighter), and a pixel is flagged `ghost` when
// chi2 / 3 > dof + ghost_sigmas * sqrt(2 dof). With `deghost`, a ghost pixel's value is the
// longest usable bracket's alone (one consistent scene instead of a blend of two; noisier).
// Output radiance is X / e: the signal normalised to saturation per unit relative exposure,
// i.e. L_scene * k / X_sat in the capture convention X = L * e * k (camera gain k).
#pragma once

#include "hdr/bracket_set.h"
#include "hdr/noise_model.h"
#include "hdr/response_curve.h"

#include <opencv2/core.hpp>

namespace rsibr {

// kOutside: no photo there (a view placed on a larger canvas, calib/lens/far_camera.h); never written.
enum MergeFlag : unsigned char { kClipped = 1, kBlack = 2, kGhost = 4, kOutside = 8 };

struct MergeOptions {
  int saturation_code = -1;   // every channel's; -1: the curve's per-channel saturation codes
  bool pilot_pass = true;     // false: weights from the measured X_j (biased; for comparisons)
  double model_error = 0.03;  // relative error allowed for the curve in the ghost test
  double ghost_sigmas = -1;   // -1: 6, or 8 for lossy files (compression errors have heavier tails)
  bool deghost = false;       // ghost pixels take the longest usable bracket alone (value and variance)
};

struct MergedImage {
  cv::Mat radiance;                        // CV_32FC3 RGB, X / e
  cv::Mat variance;                        // CV_32FC3, var of radiance per channel
  cv::Mat flags;                           // CV_8UC1, MergeFlag bits
  long clipped = 0, black = 0, ghost = 0;  // pixel counts
};

// Throws std::invalid_argument when curve.max_code differs from the brackets' or there are more
// than 32 brackets.
MergedImage merge_brackets(const BracketSet& brackets, const ResponseCurve& curve, const NoiseModel& noise,
                           const MergeOptions& options = {});

// Debevec & Malik's hat-weighted average of ln X(z_j) - ln e_j (their eq. 6), w(z) = min(z, max_code - z),
// saturated codes excluded per channel, with the same curve: the comparison baseline for the merge.
// saturation_code -1: the curve's per channel.
cv::Mat merge_hat_weighted(const BracketSet& brackets, const ResponseCurve& curve, int saturation_code = -1);

}  // namespace rsibr
