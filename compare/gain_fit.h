// The global exposure and white-balance fit of rsibr compare: one gain per channel, g_c, such
// that g_c a_c ~ b_c over every weighted texel of every view, found with Ceres under a robust
// (Cauchy) loss so that a few outliers (a sun clipped in one map, the camera's reflection) do not
// drive it. It separates a calibration offset of A (exposure, white balance) from errors of shape.
//
//   residual_pc = ln(g_c a'_pc + eps) - ln(b'_pc + eps),   x' = max(x, 0),   g_c = exp(theta_c)
//   cost        = sum_p (w_p / mean w) rho( sum_c residual_pc^2 ),   rho(s) = k^2 ln(1 + s / k^2)
// The log residual weighs a dark and a bright texel alike (HDR); eps is the log error's
// (compare/image_error.h). On noiseless data (b = g* a) every residual vanishes at g = g*, so the fit
// recovers g* to the solver's tolerance. theta starts at each channel's weighted median of
// ln(b/a) over texels where both are positive (robust already, and right even when A is many
// stops off B, where eps would flatten the cost); the loss then refines it.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

namespace rsibr {

// a, b: CV_32FC3 of one size, finite where weight > 0; weight: CV_32FC1, >= 0.
struct WeightedImages {
  cv::Mat a, b, weight;
};

struct GainFitOptions {
  double log_epsilon = 1e-3;  // eps, in radiance units (> 0)
  double loss_scale = 0.1;    // k of the Cauchy loss, in ln units (0.1: about 10 %)
  // At most this many texels enter the fit: every n-th weighted texel in view and row order
  // (deterministic). 0: all.
  long max_texels = 1 << 17;
  int max_iterations = 200;
};

struct GainFit {
  std::array<double, 3> gains{1, 1, 1};   // A is calibrated as g_c a_c
  double exposure_stops = 0;              // log2 of the luminance (Rec.709 Y) of the gains
  std::array<double, 3> chroma{1, 1, 1};  // gains / 2^exposure_stops: the white balance part
  long texels_used = 0;
  int iterations = 0;
  bool converged = false;
  double initial_cost = 0, final_cost = 0;
};

// Throws std::invalid_argument when no texel has weight. Single-threaded: same input, same bytes.
GainFit fit_gains(const std::vector<WeightedImages>& images, const GainFitOptions& options);

// One texel's residuals and their Jacobian (d residual_c / d theta_k, row-major 3x3; diagonal),
// the cost the fit hands to Ceres: residual_c = ln(exp(theta_c) a'_c + eps) - ln(b'_c + eps).
// jacobian may be null.
void log_gain_residuals(const double theta[3], const double a[3], const double b[3], double eps, double residuals[3],
                        double* jacobian);

// Returns a copy of rgb (CV_32FC3) with channel c multiplied by gains[c].
cv::Mat apply_gains(const cv::Mat& rgb, const std::array<double, 3>& gains);

}  // namespace rsibr
