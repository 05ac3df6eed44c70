// Self-calibration of the focal length from the balls' outlines. A sphere's silhouette is the cone
// of rays at angle alpha around the direction to its centre (calib/balls/ball_cone.h); through a lens of
// focal length f that cone images as an outline whose shape depends on f: for a pinhole it is an
// ellipse elongated toward the principal point, with axis ratio
//   a / b = cos(alpha) / sqrt(cos^2(theta) - sin^2(alpha))    (theta: the centre's off-axis angle)
// so a ball away from the image centre says how far from the axis it is in radians, not pixels.
// With the wrong f no cone fits the outline points as well as with the right one.
//
// The estimate: the profile likelihood over f, with fx and fy scaled together and the principal
// point and the distortion (in normalised coordinates) held,
//   C(f) = sum over balls of min over (axis, alpha) of sum_i r_i(f)^2,
// r_i the outline point's pixel distance from the fitted cone's outline (calib/balls/ball_cone.h's
// fit_cone, least squares on the points its robust fit at the starting f kept). f_hat minimises
// C; its 1 sigma is sqrt(2 s^2 / C''(f_hat)), s^2 = C(f_hat) / (points - 3 balls - 1), the residual
// variance, scaled by the Birge ratio of the balls' own estimates when they scatter more than
// their sigmas say (three balls or more), and a systematic term added in quadrature: an outline
// shape error common to all balls (shape_systematic_px), which sets the floor of what outlines can
// say about f. A ball near the image centre constrains f weakly (a / b - 1 ~ theta^2 / 2) and one at
// the edge strongly; balls whose own estimate disagrees with the others' (a round thing that is
// not a sphere) are left out.
#pragma once

#include "core/lens_model.h"
#include "core/vec.h"

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct OutlineFocalOptions {
  double min_scale = 0.5, max_scale = 2.0;  // f searched in [min, max] x the lens's fx
  int grid = 25;                            // profile samples over that range (log-spaced)
  double disagreement_sigmas = 4;           // a ball this many combined sigmas from the others is left out
  int max_points_per_ball = 400;            // outlines thinned evenly to this many points
  // The outline detector's systematic shape error (pixels on a ball's minor semi-axis): about
  // 0.035 px on the project's synthetic shoots; real cameras' demosaicing, JPEG and chromatic
  // aberration add to it.
  double shape_systematic_px = 0.05;
};

struct OutlineFocalBall {
  double focal_px = 0, sigma_px = 0;  // this ball alone (sigma infinite when it does not constrain f)
  int points = 0;
  bool used = false;
};

struct OutlineFocal {
  double focal_px = 0;       // fx of the best lens (fy scaled with it)
  double sigma_px = 0;       // 1 sigma; infinite when the outlines do not constrain f in the range
  double rms_px = 0;         // outline residual RMS at focal_px
  double birge_ratio = 1;    // the balls' scatter about focal_px over their sigmas; sigma_px is scaled by it when > 1
  double systematic_px = 0;  // the shape systematic's share of sigma_px (in quadrature)
  int balls_used = 0, points = 0;
  std::vector<OutlineFocalBall> balls;  // per input outline
  std::string note;                     // why balls were left out or f is unconstrained (empty: nothing to say)
};

// `outlines`: per ball and view, its outline points in pixels (at least 8 each to be used). Throws
// std::invalid_argument when no outline has enough points.
OutlineFocal focal_from_outlines(const std::vector<std::vector<Vec2>>& outlines, const LensModel& lens,
                                 const OutlineFocalOptions& options = {});

// `lens` with fx = f and fy scaled by the same factor (principal point and distortion held).
LensModel with_focal(const LensModel& lens, double f);

}  // namespace rsibr
