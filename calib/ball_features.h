// Features in the chrome ball for the orientation solve (calib/orientation_solve.h): SIFT on the
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

#include "calib/ball_cone.h"
#include "calib/orientation_solve.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

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

// Observations for solve_orientations; *features gets the number of tracks. Tracks seen by one view
// only are dropped; a track with two features of one view keeps the first.
std::vector<DirectionObservation> match_ball_features(const std::vector<BallFeatures>& views, int* features,
                                                      double ratio = 0.75);

}  // namespace rsibr
