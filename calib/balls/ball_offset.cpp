#include "calib/balls/ball_offset.h"

#include <Eigen/Cholesky>

#include <cmath>

namespace rsibr {
namespace {

Vec3 centre_in_own_radii(const BallCone& cone) { return cone.axis / std::sin(cone.half_angle); }

Mat3 centre_covariance(const BallCone& cone) {
  const double sa = std::sin(cone.half_angle), ca = std::cos(cone.half_angle);
  const double across = 1 / (sa * sa), along = ca * ca / (sa * sa * sa * sa);
  return across * Mat3::Identity() + (along - across) * cone.axis * cone.axis.transpose();
}

}  // namespace

Vec3 implied_ball_offset(const BallOffsetView& v, double scale) {
  return v.world_from_cam * (scale * centre_in_own_radii(v.ball) - centre_in_own_radii(v.chrome));
}

Mat3 implied_ball_offset_covariance(const BallOffsetView& v, double scale) {
  const Mat3 cam = scale * scale * centre_covariance(v.ball) + centre_covariance(v.chrome);
  return v.world_from_cam * cam * v.world_from_cam.transpose();
}

std::optional<Vec3> weighted_ball_offset(const std::vector<BallOffsetView>& views, double scale) {
  if (views.empty()) return std::nullopt;
  Mat3 information = Mat3::Zero();
  Vec3 weighted = Vec3::Zero();
  for (const BallOffsetView& v : views) {
    const Mat3 inverse = implied_ball_offset_covariance(v, scale).inverse();
    information += inverse;
    weighted += inverse * implied_ball_offset(v, scale);
  }
  const Vec3 offset = information.ldlt().solve(weighted);
  if (!offset.allFinite()) return std::nullopt;
  return offset;
}

}  // namespace rsibr
