// Pictures of a comparison (rsibr compare): per-texel error heat maps in a perceptually ordered
// colour map (OpenCV's viridis: lightness rises monotonically with the value), and side-by-side
// panels A | B | heat map with labels and a scale bar, plus a contact sheet of all views. A and B
// go through the OpenColorIO display transform (core/colour.h) at one exposure. All images are
// CV_8UC3 in BGR order, ready for cv::imwrite.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rsibr {

// Colour of texels with no weight (outside the disc, zero confidence) in a heat map, BGR.
inline const cv::Vec3b kNoWeightColour(64, 64, 64);

// value / max clamped to [0, 1] through viridis (non-finite values saturate); weight 0: kNoWeightColour.
// error, weight: CV_32FC1 of one size; max > 0.
cv::Mat heat_map_bgr(const cv::Mat& error, const cv::Mat& weight, double max);

// The colour map as a horizontal bar, 0 at the left and max at the right.
cv::Mat colour_bar_bgr(int width, int height);

// A scale for heat maps from the errors: the weighted texels' q-quantile (by count) rounded up
// to 1, 2 or 5 times a power of ten, at least min_max. Deterministic.
double heat_scale_max(const std::vector<cv::Mat>& errors, const std::vector<cv::Mat>& weights, double q = 0.99,
                      double min_max = 0.01);

struct SideBySideInput {
  cv::Mat a_rgb, b_rgb;      // CV_32FC3 scene-linear working space
  cv::Mat error, weight;     // CV_32FC1
  float exposure_stops = 0;  // display exposure of A and B
  double heat_max = 1;       // the heat map's scale
  std::string title;         // e.g. "view.003  (0.00, 1.00, 0.00)"
  std::string a_label = "A", b_label = "B", heat_label = "error";
  std::string unit = "stops";
};

// [title] / A | B | heat / colour bar with ticks 0, max/2, max under the heat map. Small maps are
// magnified (nearest texel) to at least min_panel pixels a side; large ones shrunk (area
// average) to at most max_panel.
cv::Mat side_by_side(const SideBySideInput& in, int min_panel = 192, int max_panel = 768);

// The panels in a grid (ceil(sqrt(n)) columns), each scaled to the width of the widest thumbnail
// (thumb_width pixels), on a dark background.
cv::Mat contact_sheet(const std::vector<cv::Mat>& panels, int thumb_width = 480);

// The panels' exposure: core/preview_exposure.h.

}  // namespace rsibr
