// How well two oriented views agree where both see the same direction: the measure of an
// orientation that needs no truth. For every direction of a world lat-long that both chrome balls
// show cleanly (inside max_radius_fraction of the ball's angular radius, away from the camera's
// own reflection, not clipped, not outside the photo), the log2 ratio of the two views' luminance.
// Its median is the exposure offset between the views (stops; 0 when the merge's radiance scale is
// shared); the median absolute deviation around it is the mismatch, which a wrong rotation, a wrong
// ball or parallax raise. Weights: the texel's solid angle.
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/view_image.h"
#include "core/lens_model.h"

namespace rsibr {

struct AgreementOptions {
  int width = 256;  // of the world lat-long sampled (height width / 2)
  double max_radius_fraction = 0.9;
  double camera_mask_deg = 25;
};

struct ViewAgreement {
  double overlap = 0;            // fraction of the sphere both see cleanly
  double median_log2_ratio = 0;  // log2(a / b), stops
  double mismatch_stops = 0;     // median |log2(a / b) - median|
  int samples = 0;
};

// Views as merged (hdr/; flags bits hdr/merge.h), each with its chrome ball's cone and
// world_from_cam. A pair with no direction in common gives samples 0.
ViewAgreement view_agreement(const ViewImage& a, const BallCone& cone_a, const Mat3& world_from_a, const ViewImage& b,
                             const BallCone& cone_b, const Mat3& world_from_b, const LensModel& lens,
                             const AgreementOptions& options = {});

}  // namespace rsibr
