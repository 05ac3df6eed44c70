// A ball's offset from views whose cones' sizes are biased: the weighted estimate uses the views'
// directions, the plain mean carries the depth errors.
#include "calib/balls/ball_offset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

// A cone of a ball of `radius` at `centre` (camera frame), its half angle scaled by `size_error`.
BallCone cone_of(const Vec3& centre, double radius, double size_error) {
  return {centre.normalized(), std::asin(radius / centre.norm()) * size_error};
}

// A camera on a ring around the origin at `azimuth`, 1 m away, looking at the chrome ball.
Mat3 world_from_cam_at(double azimuth, Vec3& camera) {
  camera = Vec3(std::sin(azimuth), 0.2, std::cos(azimuth));
  const Vec3 z = (-camera).normalized(), x = Vec3(0, 1, 0).cross(z).normalized(), y = z.cross(x);
  Mat3 r;
  r << x, y, z;
  return r;
}

TEST(BallOffset, OneExactViewGivesTheTrueOffset) {
  Vec3 camera;
  const Mat3 r = world_from_cam_at(0.4, camera);
  const Vec3 chrome(0, 0, 0), grey(0.3, 0.01, -0.05);  // metres; chrome radius 0.05
  const BallOffsetView v{r, cone_of(r.transpose() * (chrome - camera), 0.05, 1),
                         cone_of(r.transpose() * (grey - camera), 0.04, 1)};
  const auto o = weighted_ball_offset({v}, 0.8);
  ASSERT_TRUE(o);
  EXPECT_LT((*o - grey / 0.05).norm(), 1e-9);
  EXPECT_LT((implied_ball_offset(v, 0.8) - grey / 0.05).norm(), 1e-9);
}

TEST(BallOffset, BiasedSizesAreOutweighedByTheOtherViewsDirections) {
  const Vec3 grey(0.3, 0.0, 0.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> size(1.0, 0.01);  // 1% errors in the cones' half angles
  std::vector<BallOffsetView> views;
  Vec3 mean = Vec3::Zero();
  for (int i = 0; i < 4; ++i) {
    Vec3 camera;
    const Mat3 r = world_from_cam_at(0.2 + 1.4 * i, camera);
    views.push_back({r, cone_of(r.transpose() * (-camera), 0.05, size(rng)),
                     cone_of(r.transpose() * (grey - camera), 0.05, size(rng))});
    mean += implied_ball_offset(views.back(), 1.0) / 4;
  }
  const auto o = weighted_ball_offset(views, 1.0);
  ASSERT_TRUE(o);
  const double weighted_error = (*o - grey / 0.05).norm(), mean_error = (mean - grey / 0.05).norm();
  EXPECT_LT(weighted_error, 0.3 * mean_error) << weighted_error << " " << mean_error;
  EXPECT_LT(weighted_error, 0.03);
}

TEST(BallOffset, NoViewsNoOffset) { EXPECT_FALSE(weighted_ball_offset({}, 1.0)); }

}  // namespace
}  // namespace rsibr
