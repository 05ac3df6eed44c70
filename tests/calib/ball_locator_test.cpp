// calib/balls/ball_cone.h and calib/balls/ball_locator.h: the cone fit against exact cones, and ball
// localisation on rendered views against the true centre pixel.
#include "calib/balls/ball_locator.h"

#include "calib_cases.h"

#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

LensModel wide_lens(int w, int h) {
  return LensModel("LENSMODEL_OPENCV8",
                   {260, 262, w / 2.0 - 0.3, h / 2.0 + 0.4, -0.2, 0.04, 0.001, -0.0005, 0, 0, 0, 0}, w, h);
}

// Rays exactly on a cone (through a distorted lens), plus 20% wild outliers: the robust fit
// recovers the axis and angle to rounding.
TEST(BallCone, RobustFitRecoversAnExactConeDespiteOutliers) {
  const LensModel lens = wide_lens(400, 300);
  BallCone truth;
  truth.axis = Vec3(0.5, -0.2, 1).normalized();
  truth.half_angle = 0.05;
  std::vector<Vec3> rays;
  for (const Vec2& p : cone_outline(truth, lens, 100)) rays.push_back(lens.unproject(p));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int added = 0; added < 25;) {  // outliers at least 0.02 rad (5 px) off the cone
    const Vec3 d = (truth.axis + Vec3(u(rng), u(rng), u(rng))).normalized();
    if (std::abs(cone_residual(truth, d)) < 0.02) continue;
    rays.push_back(d);
    ++added;
  }
  const ConeFit fit = fit_cone(rays, lens);
  EXPECT_LT(angle_between(fit.cone.axis, truth.axis), 1e-9);
  EXPECT_NEAR(fit.cone.half_angle, truth.half_angle, 1e-9);
  EXPECT_GE(fit.inliers, 100);
  EXPECT_LT(fit.rms_px, 1e-6);
}

// Gaussian pixel noise of sigma on the outline: the centre pixel error shrinks like
// sigma / sqrt(n) (the fit is unbiased); checked against 5 standard errors.
TEST(BallCone, CentreErrorFromNoisyOutlineIsWithinItsStandardError) {
  const LensModel lens = wide_lens(400, 300);
  BallCone truth;
  truth.axis = Vec3(-0.3, 0.1, 1).normalized();
  truth.half_angle = 0.08;
  const double sigma = 0.3;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0, sigma);
  const std::vector<Vec2> outline = cone_outline(truth, lens, 200);
  std::vector<Vec3> rays;
  for (const Vec2& p : outline) rays.push_back(lens.unproject(p + Vec2(g(rng), g(rng))));
  const ConeFit fit = fit_cone(rays, lens);
  const double err = (lens.project(fit.cone.axis) - lens.project(truth.axis)).norm();
  // A circle's centre from n points with radial noise sigma: std error sigma * sqrt(2/n) per axis.
  EXPECT_LT(err, 5 * sigma * std::sqrt(2.0 / 200) * std::sqrt(2.0));
  EXPECT_NEAR(fit.rms_px, sigma, 0.2 * sigma);  // the radial component of the 2-D noise
}

TEST(BallCone, TooFewOrDegenerateRaysAreRefused) {
  const LensModel lens = LensModel::pinhole(100, 64, 48);
  EXPECT_THROW(fit_cone({Vec3(0, 0, 1), Vec3(0.1, 0, 1).normalized()}, lens), std::invalid_argument);
  // Rays on one great circle (a line in the image) are no cone in front of the camera.
  std::vector<Vec3> line;
  for (int i = 0; i < 10; ++i) line.push_back(Vec3(0.01 * i, 0, 1).normalized());
  EXPECT_THROW(fit_cone(line, lens), std::invalid_argument);
}

struct LocateCase {
  int ball;
  bool stand;
  double noise;
};

double centre_error(const testing::RenderedView& v, int ball, const BallGuess& guess) {
  const BallLocation loc = locate_ball(v.radiance, v.scene.camera.lens, guess);
  const Vec2 truth = testing::ball_centre_px(v, ball);
  const Vec3 c = testing::ball_centre_cam(v, ball);
  const double alpha = std::asin(0.5 * v.scene.balls[ball].diameter_m / c.norm());
  EXPECT_NEAR(loc.fit.cone.half_angle, alpha, 0.02 * alpha);
  return (loc.centre_px - truth).norm();
}

BallGuess rough_guess(const testing::RenderedView& v, int ball) {
  const Vec3 c = testing::ball_centre_cam(v, ball);
  const double f = v.scene.camera.lens.intrinsics()[0];
  // 3 px off and 15% too large: what a detector or a hand-placed circle gives.
  return {testing::ball_centre_px(v, ball) + Vec2(2, -2), 1.15 * f * 0.5 * v.scene.balls[ball].diameter_m / c.norm()};
}

// Chrome and grey balls with the stand and photographer in the shot and 2% noise: the centre
// pixel within 0.1 px of the projection of the true centre.
TEST(BallLocator, CentreWithinATenthOfAPixelForChromeAndGreyWithTheStand) {
  const auto v = testing::render_view(testing::rig_scene(LensModel::pinhole(420, 240, 160), 0.7), 0, 0.02);
  for (int ball = 0; ball < 2; ++ball) {
    const double err = centre_error(v, ball, rough_guess(v, ball));
    std::printf("  %s ball: centre error %.4f px\n", v.scene.balls[ball].name.c_str(), err);
    EXPECT_LT(err, 0.1) << v.scene.balls[ball].name;
  }
}

// A distorted wide lens, the ball off-axis: the cone fit through unprojected rays is exact where
// a circle fit in pixels would not be.
TEST(BallLocator, CentreWithinATenthOfAPixelThroughADistortedLens) {
  const auto v = testing::render_view(testing::rig_scene(wide_lens(240, 160), 0.45, true, -8), 0, 0.01);
  for (int ball = 0; ball < 2; ++ball) {
    const double err = centre_error(v, ball, rough_guess(v, ball));
    std::printf("  %s ball: centre error %.4f px\n", v.scene.balls[ball].name.c_str(), err);
    EXPECT_LT(err, 0.1) << v.scene.balls[ball].name;
  }
}

// The chrome ball cut by the image's left edge (camera turned right): the visible part of the
// outline still pins the centre.
TEST(BallLocator, BallCutByTheImageEdgeIsStillLocated) {
  const auto v = testing::render_view(testing::rig_scene(LensModel::pinhole(420, 240, 160), 0.7, true, 8), 0, 0.02);
  const Vec2 truth = testing::ball_centre_px(v, 0);
  ASSERT_LT(truth.x(), 30) << "the case must put the ball at the edge";
  const double err = centre_error(v, 0, rough_guess(v, 0));
  std::printf("  chrome ball at x = %.1f px: centre error %.4f px\n", truth.x(), err);
  EXPECT_LT(err, 0.1);
}

TEST(BallLocator, NoBallThereIsAClearError) {
  const auto v = testing::render_view(testing::rig_scene(LensModel::pinhole(420, 240, 160), 0.7, false), 0, 0.02);
  // The sky above the balls.
  try {
    locate_ball(v.radiance, v.scene.camera.lens, {Vec2(120, 20), 15});
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ball at (120.0, 20.0)"), std::string::npos) << e.what();
  }
}

TEST(BallLocator, DetectionFindsBothBallsCloseEnoughToLocate) {
  const auto v = testing::render_view(testing::rig_scene(LensModel::pinhole(420, 240, 160), 0.7), 0, 0.02);
  const auto guesses = detect_balls(v.radiance, 15, 60, 4);
  for (int ball = 0; ball < 2; ++ball) {
    const Vec2 truth = testing::ball_centre_px(v, ball);
    bool found = false;
    for (const BallGuess& g : guesses) found |= (g.centre_px - truth).norm() < 4;
    EXPECT_TRUE(found) << v.scene.balls[ball].name;
  }
}

}  // namespace
}  // namespace rsibr
