// What a comparison reports (compare/map_compare.h): its JSON and its side-by-side pictures, the
// same for `rsibr compare` and the compare step of `rsibr process` (each adds what only it knows:
// file names, the ball, the views left out).
//
// JSON: {"settings": {log_epsilon, psnr_peak, psnr_cap_db}, "overall": {before, after, texels,
// weight}, "fit": {gains, exposure_stops, chroma, texels_used, iterations, converged,
// initial_cost, final_cost} or null, "heat_map": {quantity, unit, min, max, display_exposure_stops},
// "views": [{name, texels, weight, before, after; for map sets: a_part, b_part, view, angle_deg,
// frame_angle_deg, b_resampled_to_a_frame}]}; metrics as {relative_rms, log_rms_stops, psnr_db,
// psnr_capped, mse, mean_a, mean_b}.
#pragma once

#include "compare/map_compare.h"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace rsibr {

nlohmann::json error_metrics_json(const ErrorMetrics& m);

// Each pair's log error image (after the fit, when there is one), the heat maps' scale and the
// display exposure the pictures share.
struct ComparisonImages {
  std::vector<cv::Mat> a_fitted;  // A times the fitted gains (A as read without a fit), CV_32FC3
  std::vector<cv::Mat> errors;    // log2 error per texel, CV_32FC1
  double heat_max = 1;            // stops
  float exposure_stops = 0;
};

// heat_max > 0 and a finite exposure are used as given; else from the errors (the weighted 99th
// percentile, compare/compare_pictures.h) and B's weighted texels (core/preview_exposure.h).
ComparisonImages comparison_images(const Comparison& c, double heat_max = 0, float exposure_stops = NAN);

// The JSON above. `map_sets`: the pairs are views of map sets (their parts and directions listed).
nlohmann::json comparison_json(const Comparison& c, const ComparisonImages& images, bool map_sets);

// Pair i's panel: A (x gains) | B | heat map, titled `title`.
cv::Mat comparison_panel(const Comparison& c, const ComparisonImages& images, std::size_t i, const std::string& title,
                         const std::string& a_label, const std::string& b_label);

}  // namespace rsibr
