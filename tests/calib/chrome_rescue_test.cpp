// calib/balls/ball_identification.h, rescue_chrome_balls: a chrome ball the appearance test missed is
// taken from the rotation-invariant distance to another ball, and only when exactly one candidate
// lies there.
#include "calib/balls/ball_identification.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// A candidate of a ball whose centre is at `centre_m` (camera frame, metres) with radius `radius_m`,
// with a clean outline and the given appearance measures.
BallCandidate candidate(const Vec3& centre_m, double radius_m, double rim_texture, double diffuse_residual,
                        double shading_texture) {
  BallCandidate c;
  c.loc.fit.cone.axis = centre_m.normalized();
  c.loc.fit.cone.half_angle = std::asin(radius_m / centre_m.norm());
  c.loc.fit.rms_px = 0.2;
  c.loc.fit.inliers = 95;
  c.loc.outline_px.resize(100);
  c.loc.centre_px = Vec2(500 + 1000 * centre_m.x() / centre_m.z(), 400 + 1000 * centre_m.y() / centre_m.z());
  c.loc.radius_px = 1000 * radius_m / centre_m.z();
  c.inlier_fraction = 0.95;
  c.outline_support = 0.95;
  c.frame_fraction = 1;
  c.texture = 0.05;
  c.rim_texture = rim_texture;
  c.diffuse_residual = diffuse_residual;
  c.shading_texture = shading_texture;
  c.rim_radial = 0.45;  // a ball's rim, as chrome balls measure
  return c;
}

BallCandidate chrome_at(const Vec3& c) { return candidate(c, 0.05, 0.4, 0.35, 0.04); }
BallCandidate smooth_chrome_at(const Vec3& c) { return candidate(c, 0.05, 0.2, 0.35, 0.04); }  // no chrome test passes
BallCandidate grey_at(const Vec3& c) { return candidate(c, 0.05, 0.0, 0.01, 0.002); }

const std::vector<ListedBall> kBalls = {{"chrome", BallKind::chrome, 0.1}, {"grey", BallKind::grey, 0.1}};

// A view of the rig (chrome at the origin, grey 0.15 m to its side) from `eye`, with extra candidates.
ViewCandidates view_of(const Vec3& eye, bool smooth, std::vector<BallCandidate> extra = {}) {
  const Vec3 chrome = -eye, grey = Vec3(0.15, 0, 0) - eye;
  ViewCandidates vc;
  vc.cands = {smooth ? smooth_chrome_at(chrome) : chrome_at(chrome), grey_at(grey)};
  for (BallCandidate& e : extra) vc.cands.push_back(e);
  vc.pick = assign_balls_in_view(vc.cands, kBalls);
  return vc;
}

TEST(ChromeRescue, AChromeBallTooSmoothForTheAppearanceTestIsTakenAtTheRigsDistance) {
  std::vector<std::optional<ViewCandidates>> views = {
      view_of(Vec3(0.1, 0.2, -1.0), false), view_of(Vec3(-0.2, 0.1, -1.2), false), view_of(Vec3(0.0, 0.3, -0.9), false),
      view_of(Vec3(0.3, 0.2, -1.1), true)};
  ASSERT_EQ(views[3]->pick[0], -1);  // the appearance test misses it
  ASSERT_EQ(views[3]->pick[1], 1);
  const std::vector<ChromeRescue> r = rescue_chrome_balls(views, kBalls);
  for (int v = 0; v < 3; ++v) EXPECT_EQ(r[std::size_t(v)].candidate, -1);  // found anyway: nothing to rescue
  EXPECT_EQ(r[3].candidate, 0);
  EXPECT_NE(r[3].note.find("grey"), std::string::npos) << r[3].note;
}

TEST(ChromeRescue, ACircleAtAnotherDistanceIsNotTakenAndTwoAtTheRightOneAreAmbiguous) {
  const Vec3 eye(0.3, 0.2, -1.1);
  // The smooth chrome ball plus a glossy-looking background circle 0.5 m behind the grey ball: only
  // the ball is taken.
  ViewCandidates one = view_of(eye, true, {candidate(Vec3(0.15, 0, 0.5) - eye, 0.05, 0.2, 0.4, 0.05)});
  // A second glossy-looking circle at the same distance from the grey ball (mirrored across it).
  ViewCandidates two = view_of(eye, true, {candidate(Vec3(0.30, 0, 0) - eye, 0.05, 0.2, 0.4, 0.05)});
  std::vector<std::optional<ViewCandidates>> views = {view_of(Vec3(0.1, 0.2, -1.0), false),
                                                      view_of(Vec3(-0.2, 0.1, -1.2), false), one, two, std::nullopt};
  const std::vector<ChromeRescue> r = rescue_chrome_balls(views, kBalls);
  EXPECT_EQ(r[2].candidate, 0);
  EXPECT_EQ(r[3].candidate, -1);
  EXPECT_EQ(r[4].candidate, -1);
}

TEST(ChromeRescue, WithoutDiametersOrOtherViewsThatAgreeNothingIsRescued) {
  std::vector<std::optional<ViewCandidates>> views = {
      view_of(Vec3(0.1, 0.2, -1.0), false), view_of(Vec3(-0.2, 0.1, -1.2), false), view_of(Vec3(0.3, 0.2, -1.1), true)};
  const std::vector<ListedBall> no_sizes = {{"chrome", BallKind::chrome, {}}, {"grey", BallKind::grey, {}}};
  EXPECT_EQ(rescue_chrome_balls(views, no_sizes)[2].candidate, -1);
  // One view with both balls is no agreement.
  std::vector<std::optional<ViewCandidates>> few = {views[0], views[2]};
  EXPECT_EQ(rescue_chrome_balls(few, kBalls)[1].candidate, -1);
  // A grey-looking candidate at the right distance is never taken for the chrome ball.
  ViewCandidates grey_twin = view_of(Vec3(0.3, 0.2, -1.1), true);
  grey_twin.cands[0] = grey_at(-Vec3(0.3, 0.2, -1.1));
  grey_twin.pick = assign_balls_in_view(grey_twin.cands, kBalls);
  ASSERT_EQ(grey_twin.pick[0], -1);
  std::vector<std::optional<ViewCandidates>> g = {views[0], views[1], grey_twin};
  EXPECT_EQ(rescue_chrome_balls(g, kBalls)[2].candidate, -1);
}

}  // namespace
}  // namespace rsibr
