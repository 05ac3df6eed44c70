// A ball's place relative to the chrome ball from several views whose rotations are known: each
// view's chrome cone and the ball's cone imply an offset (world, chrome radii), known well across
// the view's axis and poorly along it (a cone's distance comes from its half angle, 1/alpha times
// less precise than its direction: about 20x for a ball 1 m away at 700 px focal length). The
// offsets are combined by their inverse covariances, so the other views' directions pin each
// view's depth. (The rig fit, calib/balls/ball_identification.h, keeps their plain mean: its checks
// measure each view's 3D disagreement with it.)
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/vec.h"

#include <optional>
#include <vector>

namespace rsibr {

struct BallOffsetView {
  Mat3 world_from_cam = Mat3::Identity();
  BallCone chrome;  // camera frame
  BallCone ball;    // camera frame
};

// The offset one view implies for a ball of radius `scale` chrome radii: R (scale g - c), g and c
// the cones' centres in units of their own radius.
Vec3 implied_ball_offset(const BallOffsetView& v, double scale);

// Its covariance (world, up to one common factor: one angular error sigma for outline centres and
// radii): a centre at distance |x| = 1/sin(alpha) radii is known to |x| sigma across its axis and
// to cos(alpha)/sin^2(alpha) sigma along it.
Mat3 implied_ball_offset_covariance(const BallOffsetView& v, double scale);

// The inverse-covariance weighted offset of the views (nullopt without views). One view gives its
// own offset.
std::optional<Vec3> weighted_ball_offset(const std::vector<BallOffsetView>& views, double scale);

}  // namespace rsibr
