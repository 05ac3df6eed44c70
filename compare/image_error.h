// Error metrics between two radiance images A and B over a weight image (confidence x footprint),
// per image and pooled over many (per view and overall, for rsibr compare). B is the reference.
//
// For texels p with weight w_p > 0 and channels c in {R,G,B}:
//   relative RMS   = sqrt( sum_p w_p sum_c (a_pc - b_pc)^2 / sum_p w_p sum_c b_pc^2 )
//   log RMS        = sqrt( sum_p w_p sum_c log2((a'_pc + eps)/(b'_pc + eps))^2 / (3 sum_p w_p) )  [stops]
//                    with x' = max(x, 0): an HDR merge's noise may dip below zero; eps > 0 keeps
//                    black texels finite and damps relative noise far below the signal
//   MSE            = sum_p w_p sum_c (a_pc - b_pc)^2 / (3 sum_p w_p)
//   PSNR           = 10 log10( peak^2 / max(MSE, (peak 2^-24)^2) )                           [dB]
//                    peak is a stated value (for HDR data: the reference's largest weighted
//                    value, ErrorSettings); the floor is one float32 rounding step at the peak,
//                    so identical images give the cap 20 log10(2^24) = 144.5 dB, never Inf.
// Pooling sums the numerators and denominators, so "overall" weighs every texel alike.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <string>

namespace rsibr {

inline constexpr double kPsnrCapDb = 144.49439791871097;  // 20 log10(2^24)

struct ErrorSettings {
  double log_epsilon = 1e-3;  // eps of the log error, in the images' radiance units (> 0)
  double psnr_peak = 1.0;     // the peak of the PSNR (> 0)
};

// Accumulated weighted sums; add() one image pair or merge() two accumulations, then metrics().
struct ErrorSums {
  double weight = 0;                                     // sum_p w_p
  long texels = 0;                                       // texels with w_p > 0
  double squared_error = 0;                              // sum_p w_p sum_c (a-b)^2
  double squared_reference = 0;                          // sum_p w_p sum_c b^2
  double squared_log = 0;                                // sum_p w_p sum_c log2(...)^2
  std::array<double, 3> sum_a{0, 0, 0}, sum_b{0, 0, 0};  // sum_p w_p a_pc, sum_p w_p b_pc

  void merge(const ErrorSums& other);
};

struct ErrorMetrics {
  double relative_rms = 0;
  double log_rms_stops = 0;
  double mse = 0;
  double psnr_db = kPsnrCapDb;
  bool psnr_capped = true;  // MSE at or below the float32 floor
  double weight = 0;
  long texels = 0;
  std::array<double, 3> mean_a{0, 0, 0}, mean_b{0, 0, 0};  // weighted channel means
};

// a, b: CV_32FC3 of one size; weight: CV_32FC1 of that size, finite and >= 0. The caller checks
// that a and b are finite where weight > 0 (map_compare does). Rows are summed in parallel and
// reduced in row order, so the result does not depend on the thread count. gains_a multiply A's
// channels first, in double precision (a fitted gain times a float near its maximum stays finite).
ErrorSums error_sums(const cv::Mat& a, const cv::Mat& b, const cv::Mat& weight, const ErrorSettings& settings,
                     const std::array<double, 3>& gains_a = {1, 1, 1});

// Throws std::invalid_argument when no texel has weight, or when the reference is zero over the
// weighted texels but A is not (the relative error has no scale); identical zeros give 0.
ErrorMetrics error_metrics(const ErrorSums& sums, const ErrorSettings& settings);

// The heat-map quantity per texel: sqrt( sum_c log2((a' + eps)/(b' + eps))^2 / 3 ), in stops,
// as CV_32FC1; 0 where weight is 0; A's channels times gains_a first.
cv::Mat log_error_image(const cv::Mat& a, const cv::Mat& b, const cv::Mat& weight, double log_epsilon,
                        const std::array<double, 3>& gains_a = {1, 1, 1});

}  // namespace rsibr
