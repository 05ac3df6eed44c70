// The stand under a ball as a vertical line: a pole (a light stand, a tripod's column) holds the
// ball from below, so its axis is the vertical through the ball's centre C, and the plane through the
// camera centre and that axis contains the world's up (calib/orientation/world_up.h, VerticalLine).
//
// In the image the axis passes through c = project(C), the ball centre's pixel, heading roughly
// down (cameras are held upright). Searched over its direction phi (within max_angle_deg of image
// down, 0.25-degree steps) and the pole's half width h (0.1 to 0.7 ball radii): along the line,
// from 1.25 to 4 ball radii below c, the log luminance is differenced across the line at c + t d +-
// h n (d the direction, n its normal, 1 px either side); a pole shows two edges of opposite sign
// (its two sides against one background) at every t. Score: the mean over t of the weaker edge's
// contrast where the signs oppose (0 elsewhere). The best (phi, h) must score at least
// `min_contrast` with opposing edges on `min_coverage` of the samples, and stand out from the
// score of the directions beyond 3 pole widths (a wall's edge, a shadow are not poles); phi is refined
// by a parabola through its neighbours. The plane's normal is unproject(c) x unproject(c + 100 d)
// (camera frame); its std dev from the score's curvature, at least 0.1 degrees.
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <optional>

namespace rsibr {

struct StandLineOptions {
  double max_angle_deg = 35;
  double min_contrast = 0.08;  // natural log units
  double min_coverage = 0.6;
  double min_distinction = 2.0;  // best score over the best score away from it
  // How vertical a stand is (levelled by eye): a tilt every view of it shares, so n lines of one
  // stand are given sigma_i = max(measured, verticality_deg * sqrt(n)) (their mean no better than it).
  double verticality_deg = 0.5;
};

struct StandLine {
  Vec3 plane_normal;     // unit, camera frame
  double angle_deg = 0;  // the line's direction in the image, from image down toward +x
  double half_width_px = 0;
  double score = 0, coverage = 0, distinction = 0;
  double sigma_deg = 0.1;
};

// `image` CV_32FC3 RGB linear of the lens's size; `ball` the ball's cone. nullopt when no pole
// qualifies.
std::optional<StandLine> find_stand_line(const cv::Mat& image, const LensModel& lens, const BallCone& ball,
                                         const StandLineOptions& options = {});

}  // namespace rsibr
