// Comparing two radiance maps: two map sets with matching views (captured against computed, or
// any two), a map set and a one-view map set, or two environments. B is the reference.
//
// Views are paired by direction: every view of the smaller set must have a view of the other set
// within the tolerance; the pairs are compared. Where a pair's frames differ (a captured view's
// roll about its axis, the small tilt allowed by the tolerance), B is resampled into A's frame
// (bilinear; texels whose taps leave B's disc get no weight). Texel weights: sphere maps count the texels whose centres lie
// inside the unit disc (image-plane area, as the camera sees the ball), times the confidence of
// each map that has one (captured maps); environments in other layouts weigh texels by solid
// angle. Metrics (compare/image_error.h) per pair and pooled over all pairs, before and after the
// global gain fit (compare/gain_fit.h); the log error's eps and the PSNR's peak are the same for all.
#pragma once

#include "core/env_map.h"
#include "compare/gain_fit.h"
#include "compare/image_error.h"
#include "formats/map_set.h"

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct CompareOptions {
  std::string name_a = "A", name_b = "B";  // how errors name the inputs (file paths in the CLI)
  // eps of the log error = this fraction of B's level: the weighted median over all pairs' texels
  // of B's channel mean (robust to a sun); B's weighted mean where that median is 0, else A's, else 1.
  double log_epsilon_fraction = 1e-2;
  double psnr_peak = 0;  // > 0: this peak; 0: B's largest weighted value (the HDR peak)
  double view_tolerance_deg = 0.5;
  bool fit = true;             // the global gain fit (metrics "after" equal "before" without it)
  GainFitOptions fit_options;  // its log_epsilon is replaced by the eps above
};

struct PairComparison {
  std::string name;  // "view.003" (A's part), or the environment's name
  int index_a = 0, index_b = 0;
  Vec3 view = Vec3::Zero();    // A's view direction (zero for an environment)
  double angle_deg = 0;        // between A's and B's view directions
  double frame_angle_deg = 0;  // rotation between A's and B's frames (roll and tilt)
  bool b_resampled = false;    // B was resampled into A's frame
  WeightedImages images;       // A as read, B (in A's frame), the weights
  ErrorMetrics before, after;
};

struct Comparison {
  std::vector<PairComparison> pairs;
  ErrorMetrics before, after;
  std::optional<GainFit> fit;
  ErrorSettings settings;  // the eps and peak used
};

// 1 for texels whose centre lies inside the unit disc, 0 outside, times each non-empty
// confidence (CV_32FC1 of the same size). CV_32FC1.
cv::Mat sphere_map_weight(int width, int height, const cv::Mat& confidence_a = {}, const cv::Mat& confidence_b = {});

// Solid angle per texel of the layout as CV_32FC1 (normalised to a mean of 1 over the sphere's texels).
cv::Mat solid_angle_weight(const Layout& layout);

// Pairs (index in a, index in b) of matching views, in the smaller set's order. Throws
// std::invalid_argument("<name>: view.NNN ... ") when a view has no partner within the tolerance
// or two views share one.
std::vector<std::pair<int, int>> match_views(const MapSet& a, const MapSet& b, const CompareOptions& options);

// A view's map (and confidence) resampled into another frame about nearly the same view:
// texel p gets the source's value at the normal world_from_view * g_normal(p), bilinearly; valid
// is 1 where all taps lie on source texels inside the disc, 0 elsewhere (CV_32FC1).
struct Reframed {
  cv::Mat rgb, confidence, valid;
};
Reframed reframe(const MapView& view, const Mat3& world_from_view);

// Compares prepared pairs. Throws std::invalid_argument naming the input and the pair for
// mismatched sizes, non-finite pixels or invalid weights where weight > 0, and no weight at all.
Comparison compare_pairs(std::vector<PairComparison> pairs, const CompareOptions& options);

// Map sets: matched views, sphere-map weights. Also refuses sets that differ in size or in
// albedo normalisation (texels would not hold the same quantity).
Comparison compare_map_sets(const MapSet& a, const MapSet& b, const CompareOptions& options);

// Environments of the same layout and size: sphere layouts weigh the disc, others solid angle.
Comparison compare_environments(const EnvMap& a, const EnvMap& b, const CompareOptions& options);

}  // namespace rsibr
