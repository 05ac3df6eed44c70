// Features in the chrome ball for the orientation solve (calib/orientation/orientation_solve.h): SIFT on the
// tone-mapped (log) luminance inside the ball's silhouette, each keypoint turned into the world-side
// direction it reflects, with the exact per-pixel geometry: the camera ray d = lens.unproject(q) meets
// the ball (centre C = axis / sin(alpha), radius 1) at P with normal n, and the feature lies along
// r = d - 2 (d.n) n (camera frame, at infinity). The direction's angular std dev is sigma_px times
// |dr/dq| (finite differences), which grows without bound toward the rim; keypoints beyond
// max_radius_fraction of the silhouette's angular radius, and those whose r is within
// camera_mask_deg of the camera (its body and the photographer), are dropped.
// Matching: SIFT descriptors across every pair of views (Lowe's ratio test, mutual), chained into
// feature tracks by union-find; mismatches are left to the solve's rotation RANSAC and robust loss.
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/orientation/orientation_solve.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <optional>
#include <vector>

namespace rsibr {

struct BallFeatureOptions {
  int max_features = 800;
  double sigma_px = 0.3;              // keypoint localisation std dev, pixels
  double max_radius_fraction = 0.85;  // of the angular radius alpha
  double camera_mask_deg = 25;
  double contrast_threshold = 0.04;  // SIFT's (OpenCV's default); lower finds more, weaker features
};

struct BallFeatures {
  std::vector<Vec3> directions;  // camera frame, unit
  std::vector<double> sigma;     // radians
  std::vector<Vec2> pixels;
  std::vector<Vec3> rays;  // camera frame, unit: lens.unproject(pixel)
  cv::Mat descriptors;     // CV_32F, one row per feature
};

// `image` CV_32FC3 linear RGB of the lens's size.
BallFeatures ball_features(const cv::Mat& image, const LensModel& lens, const BallCone& cone,
                           const BallFeatureOptions& options = {});

// Per pair of views: the features each had, and the mutual matches kept.
struct PairMatches {
  int a = 0, b = 0;  // view indices, a < b
  int features_a = 0, features_b = 0;
  int matched = 0;
  bool gated = false;  // matched under a rotation guess
};

// Matching under a guess of each view's rotation (world_from_cam, or nullopt): in a pair whose
// views both have one, features i and j match when their world directions agree within gate_deg
// and each is the other's nearest descriptor inside that gate, gated_ratio times nearer than the
// second nearest there (a lone candidate passes). The gate keeps look-alikes elsewhere on the
// sphere from failing a true match. Chance pairs inside the gate agree with the guess and so with
// each other: their consensus is no evidence (orient_views tests it against chance). The unguided
// matches the gate did not pair are kept too, so a wrong guess loses nothing.
struct MatchGuess {
  std::vector<std::optional<Mat3>> world_from_cam;  // per view, or empty: no guess
  double gate_deg = 4;
  double gated_ratio = 0.9;
};

// Observations for solve_orientations; *features gets the number of tracks. Tracks seen by one view
// only are dropped; a track with two features of one view keeps the first. `pairs`, when given,
// gets one entry per pair of views.
std::vector<DirectionObservation> match_ball_features(const std::vector<BallFeatures>& views, int* features,
                                                      double ratio = 0.75, const MatchGuess& guess = {},
                                                      std::vector<PairMatches>* pairs = nullptr);

}  // namespace rsibr
