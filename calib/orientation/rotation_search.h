// The rotation between two views found from everything their chrome balls reflect, not from
// features: each ball's world is resampled onto a lat-long panorama of log luminance in its camera
// frame, and the rotation that best correlates the two panoramas is searched over all of SO(3),
// coarse to fine. Real views far apart, in a room with plain walls, share few SIFT features that
// survive the compression toward the rim; they share the layout of light and dark (windows,
// ceiling lamps, the floor) that a correlation of whole panoramas sees. The result gates the
// feature matching (calib/orientation/ball_features.h, match_ball_features), which then gives the precise,
// uncertain rotation.
//
// Score: the weighted zero-mean normalised cross-correlation (ZNCC) of log luminance over the
// directions both views see, weights = coverage of each panorama texel x its solid angle. Zero
// mean in log removes each view's exposure; luminance alone removes its white balance; a
// normalised score does not reward a large overlap over a small one, so overlaps under
// min_overlap of the sphere are not scored.
// Search: a grid over SO(3) (the image of the camera's +z axis on a Fibonacci sphere x a turn about
// it, both at grid_deg) at the coarsest level; the best candidates at least 2 grid steps apart are
// refined level by level by a local search over small turns about the three axes.
// Panorama: texel (u, v) of a W x H (W = 2H) lat-long has the camera-frame direction
//   theta = pi (v + 0.5) / H from the camera's -y (up in the image), phi = 2 pi (u + 0.5) / W - pi,
//   d = (sin theta sin phi, -cos theta, sin theta cos phi)   (phi = 0 is the camera's +z).
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/orientation/ball_features.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

// One level: log luminance (normalised by the weight) and the weight (coverage, 0..1) per texel.
struct PanoramaLevel {
  int width = 0, height = 0;
  std::vector<float> value, weight;
};

// Levels finest first, each half the size of the one before.
struct ReflectionPanorama {
  std::vector<PanoramaLevel> levels;
};

struct PanoramaOptions {
  int width = 256;      // finest level (height = width / 2)
  int coarsest = 32;    // width of the coarsest level
  int supersample = 3;  // per texel and axis
  // As the features' (calib/orientation/ball_features.h): the rim beyond this fraction of the ball's angular
  // radius is left out (a pixel there spans tens of degrees), and so is the camera's own
  // reflection with the photographer.
  double max_radius_fraction = 0.95;
  double camera_mask_deg = 25;
};

// `image` CV_32FC3 linear RGB of the lens's size; `flags` empty or CV_8UC1 (hdr/merge.h): kOutside
// pixels are not seen.
ReflectionPanorama reflection_panorama(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                       const BallCone& cone, const PanoramaOptions& options = {});

// The camera-frame direction of texel (u, v) (sub-texel) of a level, and its inverse.
Vec3 panorama_direction(const PanoramaLevel& level, double u, double v);
Vec2 panorama_texel(const PanoramaLevel& level, const Vec3& d);

struct RotationSearchOptions {
  double grid_deg = 10;      // coarse grid step over SO(3) (the coarsest texel is 11.25 degrees)
  int candidates = 24;       // refined from the coarse grid
  double min_overlap = 0.1;  // of the sphere's solid angle
};

struct RotationSearch {
  Mat3 b_from_a = Mat3::Identity();  // d_b = b_from_a d_a (camera frames)
  double score = -1;                 // ZNCC at the finest level, -1 when nothing overlaps enough
  // The best score of a refined candidate more than 10 degrees from the winner (-1 when none): a
  // runner-up close to the score means the panoramas do not tell the rotation.
  double runner_up = -1;
  double runner_up_deg = 0;  // its angle from the winner
  double overlap = 0;        // fraction of the sphere both see, at the winner
};

// The weighted ZNCC of b at `b_from_a` against a on one level of each; *overlap gets the overlap.
double panorama_correlation(const PanoramaLevel& a, const PanoramaLevel& b, const Mat3& b_from_a,
                            double* overlap = nullptr);

// Throws std::invalid_argument when the pyramids differ in their levels.
RotationSearch search_rotation(const ReflectionPanorama& a, const ReflectionPanorama& b,
                               const RotationSearchOptions& options = {});

}  // namespace rsibr
