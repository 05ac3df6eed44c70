// Self-calibration of the focal length from ball outlines (calib/lens/outline_focal.h): outlines of true
// cones through a known lens, with pixel noise, from a starting focal length that is wrong.
#include "calib/lens/outline_focal.h"

#include "calib/balls/ball_cone.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rsibr {
namespace {

// The outline of a ball of angular radius alpha whose centre images at `centre_px` (through the
// true lens), sampled at n points with Gaussian pixel noise.
std::vector<Vec2> outline(const LensModel& truth, const Vec2& centre_px, double alpha, int n, double noise,
                          std::mt19937_64& rng) {
  BallCone cone;
  cone.axis = truth.unproject(centre_px);
  cone.half_angle = alpha;
  std::normal_distribution<double> g(0, noise);
  std::vector<Vec2> px = cone_outline(cone, truth, n);
  for (Vec2& p : px) p += Vec2(g(rng), g(rng));
  return px;
}

// Balls spread over a 640x480 frame (centres 60-240 px from the principal point), about 40 px radius.
std::vector<std::vector<Vec2>> spread_balls(const LensModel& truth, double noise, std::mt19937_64& rng) {
  std::vector<std::vector<Vec2>> o;
  const Vec2 centres[] = {{100, 90}, {540, 120}, {420, 400}, {200, 330}, {320, 240}, {560, 380}};
  for (const Vec2& c : centres) o.push_back(outline(truth, c, 40.0 / truth.intrinsics()[0], 160, noise, rng));
  return o;
}

TEST(OutlineFocal, AWrongFocalLengthIsCorrectedWithinItsStatedSigma) {
  const LensModel truth = LensModel::pinhole(420, 640, 480);
  std::mt19937_64 rng(3);
  const auto o = spread_balls(truth, 0.1, rng);
  for (double start : {0.93, 1.08}) {
    const OutlineFocal f = focal_from_outlines(o, with_focal(truth, 420 * start));
    ASSERT_TRUE(std::isfinite(f.sigma_px)) << f.note;
    EXPECT_NEAR(f.focal_px, 420, 3 * f.sigma_px) << "start " << start;
    EXPECT_LT(f.sigma_px, 0.02 * 420) << "six balls across the frame constrain f to well under 2%";
    EXPECT_EQ(f.balls_used, 6);
    EXPECT_NEAR(f.rms_px, 0.1, 0.03);
  }
}

// The stated sigma is honest: over many noise draws the normalised errors have unit variance.
TEST(OutlineFocal, TheStatedSigmaMatchesTheScatterOverNoiseDraws) {
  const LensModel truth = LensModel::pinhole(420, 640, 480);
  double sum_z2 = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    std::mt19937_64 rng(100 + t);
    const auto o = spread_balls(truth, 0.2, rng);
    OutlineFocalOptions opt;
    opt.shape_systematic_px = 0;  // exact outlines: the statistical sigma alone
    const OutlineFocal f = focal_from_outlines(o, with_focal(truth, 400), opt);
    ASSERT_TRUE(std::isfinite(f.sigma_px));
    EXPECT_EQ(f.systematic_px, 0);
    sum_z2 += std::pow((f.focal_px - 420) / f.sigma_px, 2);
  }
  const double var = sum_z2 / trials;
  // chi^2 with 40 degrees of freedom / 40: within [0.55, 1.6] at about 99%.
  EXPECT_GT(var, 0.55);
  EXPECT_LT(var, 1.6);
}

// The outline detector's shape error is common to all balls: its share of sigma follows from the
// balls' elongation. A 0.05 px error on the minor semi-axis of a ball 40 px in radius at theta off
// the axis moves ln f by (0.05 / 40) / (sin^2 theta cos^2 theta / cos^3 ...) ~ (0.05 / 40) / theta^2:
// a floor noise cannot lower, and more balls cannot either.
TEST(OutlineFocal, TheShapeSystematicSetsAFloorThatMoreBallsDoNotLower) {
  const LensModel truth = LensModel::pinhole(420, 640, 480);
  std::mt19937_64 rng(11);
  auto o = spread_balls(truth, 0.02, rng);
  OutlineFocalOptions opt;
  opt.shape_systematic_px = 0.05;
  const OutlineFocal f = focal_from_outlines(o, with_focal(truth, 400), opt);
  ASSERT_TRUE(std::isfinite(f.systematic_px) && f.systematic_px > 0);
  EXPECT_GE(f.sigma_px, f.systematic_px);
  // The balls sit 14-33 degrees off the axis: a floor of a fraction of a percent to a percent.
  EXPECT_GT(f.systematic_px, 0.001 * 420);
  EXPECT_LT(f.systematic_px, 0.02 * 420);
  const auto twice = [&] {
    auto t = o;
    t.insert(t.end(), o.begin(), o.end());
    return t;
  }();
  const OutlineFocal g = focal_from_outlines(twice, with_focal(truth, 400), opt);
  EXPECT_NEAR(g.systematic_px, f.systematic_px, 0.05 * f.systematic_px);
  opt.shape_systematic_px = 0.1;
  EXPECT_NEAR(focal_from_outlines(o, with_focal(truth, 400), opt).systematic_px, 2 * f.systematic_px,
              0.05 * f.systematic_px);
}

// Through a distorted lens (the distortion held, in normalised coordinates) the same holds.
TEST(OutlineFocal, ADistortedLensKeepsItsDistortionAndFindsItsFocalLength) {
  const LensModel truth("LENSMODEL_OPENCV4", {380, 380, 330, 235, -0.2, 0.05, 0.001, -0.0005}, 640, 480);
  std::mt19937_64 rng(5);
  const auto o = spread_balls(truth, 0.1, rng);
  const OutlineFocal f = focal_from_outlines(o, with_focal(truth, 400));
  ASSERT_TRUE(std::isfinite(f.sigma_px)) << f.note;
  EXPECT_NEAR(f.focal_px, 380, 3 * f.sigma_px);
  EXPECT_LT(f.sigma_px, 0.02 * 380);
  const LensModel best = with_focal(truth, f.focal_px);
  EXPECT_EQ(best.intrinsics()[2], 330);
  EXPECT_EQ(best.intrinsics()[4], -0.2);
}

// A ball at the image centre alone says almost nothing about f: the sigma says so.
TEST(OutlineFocal, ABallAtTheCentreConstrainsLittleAndSaysSo) {
  const LensModel truth = LensModel::pinhole(420, 640, 480);
  std::mt19937_64 rng(7);
  const auto centre = outline(truth, Vec2(320, 240), 0.1, 200, 0.1, rng);
  const OutlineFocal f = focal_from_outlines({centre}, truth);
  EXPECT_TRUE(!std::isfinite(f.sigma_px) || f.sigma_px > 0.1 * 420) << f.sigma_px;
  EXPECT_EQ(f.balls_used, 1);
}

// A round thing that is not a sphere (its outline the cone of another focal length: a disc seen
// at a slant) is left out, and the balls' estimate stands.
TEST(OutlineFocal, AnOutlineThatIsNoSphereIsLeftOut) {
  const LensModel truth = LensModel::pinhole(420, 640, 480);
  std::mt19937_64 rng(9);
  auto o = spread_balls(truth, 0.1, rng);
  o.push_back(outline(LensModel::pinhole(250, 640, 480), Vec2(600, 60), 40.0 / 250, 160, 0.1, rng));
  const OutlineFocal f = focal_from_outlines(o, with_focal(truth, 400));
  ASSERT_EQ(f.balls.size(), 7u);
  EXPECT_FALSE(f.balls[6].used);
  EXPECT_EQ(f.balls_used, 6);
  EXPECT_NEAR(f.focal_px, 420, 3 * f.sigma_px);
  EXPECT_NE(f.note.find("left out"), std::string::npos) << f.note;
}

TEST(OutlineFocal, NoUsableOutlineIsAClearError) {
  const LensModel lens = LensModel::pinhole(420, 640, 480);
  EXPECT_THROW(focal_from_outlines({}, lens), std::invalid_argument);
  EXPECT_THROW(focal_from_outlines({{Vec2(1, 1), Vec2(2, 2)}}, lens), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
