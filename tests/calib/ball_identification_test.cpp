// Which ball is which (calib/balls/ball_identification.h), on rendered views of a chrome and a grey ball
// on stands in the CC0 lobby, with what real rooms add: a uniform disc and a ringed target behind
// the rig, and an unlisted grey sphere of ball size. Views on a ring (from 90 degrees the grey ball
// hides the chrome one, from 270 the chrome one hides the grey), one turned so the grey ball is cut
// by the frame's edge. Checked against the
// renderer's truth: every ball found where it is, nothing else taken for one.
#include "calib/balls/ball_identification.h"
#include "calib/balls/ball_locator.h"

#include "calib_cases.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::kLobby;

SynthScene clutter_scene() {
  const std::string text = R"(
rsibr_synth: 1
seed: 9
environment: {file: )" + kLobby.string() +
                           R"(, sanitize: true}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.07, 1.3, 0]}
clutter:
  - {shape: disc, centre: [0.5, 1.5, -3.0], radius_m: 0.15, albedo: [0.6, 0.6, 0.6]}
  - {shape: disc, centre: [-0.9, 1.7, -2.6], radius_m: 0.3, rings: 3, albedo: [0.9, 0.9, 0.85], ring_albedo: [0.1, 0.1, 0.1]}
  - {shape: sphere, centre: [-0.45, 1.25, -1.4], radius_m: 0.1, albedo: [0.3, 0.3, 0.3]}
  - {shape: disc, centre: [0.6, 1.2, 3.0], radius_m: 0.2, albedo: [0.5, 0.45, 0.4]}
camera: {width: 400, height: 300, lens: {model: LENSMODEL_PINHOLE, focal_px: 500}}
views:
  - {plan: ring, azimuths_deg: [15, 90, 165, 270, 320], elevation_deg: 10, distance_m: 0.9}
  - {plan: ring, azimuths_deg: [200], elevation_deg: 10, distance_m: 0.9, pan_deg: 17}
)";
  return parse_synth_scene(text, "clutter.yaml", ".");
}

struct Views {
  SynthScene scene = clutter_scene();
  std::vector<testing::RenderedView> views;
  std::vector<std::vector<BallCandidate>> candidates;
  std::vector<ListedBall> listed = {{"chrome", BallKind::chrome, 0.1}, {"grey", BallKind::grey, 0.1}};
};

const Views& rendered() {
  static Views* v = [] {
    auto* r = new Views;
    for (int i = 0; i < 6; ++i) {
      r->views.push_back(testing::render_view(r->scene, i, 0.002, 5, 2));
      r->candidates.push_back(find_ball_candidates(r->views.back().radiance, r->scene.camera.lens));
    }
    return r;
  }();
  return *v;
}

bool visible(const testing::RenderedView& v, int ball) {
  // Not hidden behind the other ball: the angle between the two centres beats the sum of radii.
  const Vec3 a = testing::ball_centre_cam(v, ball), b = testing::ball_centre_cam(v, 1 - ball);
  const double ra = std::asin(0.05 / a.norm()), rb = std::asin(0.05 / b.norm());
  return angle_between(a, b) > 0.7 * (ra + rb) || a.norm() < b.norm();
}

// The views as the cross-view stage sees them, with the true rotations and (where it shows) the
// true chrome ball as the anchor.
std::vector<ViewBalls> with_true_rotations(const Views& r) {
  std::vector<ViewBalls> vb;
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    ViewBalls v;
    v.name = "view" + std::to_string(i);
    v.candidates = r.candidates[i];
    v.world_from_cam = r.views[i].pose.world_from_cam;
    const Vec3 c = testing::ball_centre_cam(r.views[i], 0);
    if (visible(r.views[i], 0)) v.chrome = BallCone{c.normalized(), std::asin(0.05 / c.norm())};
    vb.push_back(v);
  }
  return vb;
}

// Per view, without the rotations: the chrome ball as the orientation step picks it is the true
// chrome ball in every view where it shows.
TEST(BallIdentification, TheChromeBallIsFoundAmongBackgroundCirclesInEveryView) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Views& r = rendered();
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    const std::vector<int> pick = assign_balls_in_view(r.candidates[i], r.listed);
    if (!visible(r.views[i], 0)) {
      EXPECT_EQ(pick[0], -1) << "view " << i << ": the chrome ball is hidden, nothing may stand in for it";
      continue;
    }
    ASSERT_GE(pick[0], 0) << "view " << i;
    const BallCandidate& c = r.candidates[i][std::size_t(pick[0])];
    // The outline of a mirror lies up to a few pixels inside its limb (the orientation refines it).
    EXPECT_LT((c.loc.centre_px - testing::ball_centre_px(r.views[i], 0)).norm(), 0.15 * c.loc.radius_px)
        << "view " << i;
    EXPECT_TRUE(looks_like(c, BallKind::chrome));
    EXPECT_FALSE(looks_like(c, BallKind::grey));
  }
}

// With the rotations (the truth's), the rig: the grey ball's place relative to the chrome ball is
// found (in chrome radii, world frame), and each view takes the grey ball where it is, reports it
// hidden where it hides, flags it cut where the frame cuts it, and never takes the disc or the
// unlisted sphere.
TEST(BallIdentification, AcrossViewsEveryBallIsFoundAndNothingElseIsTaken) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Views& r = rendered();
  const std::vector<ViewBalls> vb = with_true_rotations(r);
  const std::vector<RigMember> rig = fit_ball_rig(vb, r.listed);
  ASSERT_TRUE(rig[1].known);
  EXPECT_TRUE(rig[1].scale_given);
  const Vec3 true_offset = (r.scene.balls[1].centre - r.scene.balls[0].centre) / 0.05;
  EXPECT_LT((rig[1].offset - true_offset).norm(), 0.3) << rig[1].offset.transpose();
  EXPECT_GE(rig[1].support, 3);
  int found = 0, hidden = 0, cut = 0;
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    const std::vector<BallFinding> f =
        identify_view_balls(vb[i], rig, r.listed, r.views[i].radiance, r.scene.camera.lens);
    ASSERT_EQ(f.size(), 2u);
    const Vec2 truth = testing::ball_centre_px(r.views[i], 1);
    if (!vb[i].chrome) {
      // Without its chrome ball a view cannot place the others: reported, not guessed.
      EXPECT_FALSE(f[0].found());
      EXPECT_FALSE(f[1].found());
      EXPECT_NE(f[1].note.find("no chrome ball"), std::string::npos) << f[1].note;
      continue;
    }
    ASSERT_TRUE(f[0].found()) << i;
    if (f[1].found()) {
      ++found;
      EXPECT_LT((f[1].ball->loc.centre_px - truth).norm(), 1.5) << "view " << i << ": " << f[1].note;
      cut += f[1].ball->cut;
      if (!r.scene.camera.lens.in_image(truth, -0.9 * f[1].ball->loc.radius_px)) {
        EXPECT_TRUE(f[1].ball->cut) << i;
      }
    } else {
      // Missing only where it cannot be seen whole enough: hidden behind the chrome ball, or the frame.
      EXPECT_TRUE(!visible(r.views[i], 1) || !r.scene.camera.lens.in_image(truth, 0))
          << "view " << i << ": " << f[1].note;
      hidden += !visible(r.views[i], 1);
      EXPECT_FALSE(f[1].note.empty());
    }
  }
  EXPECT_GE(found, 3);
  EXPECT_EQ(hidden, 1) << "the view from 270 degrees has the grey ball behind the chrome one";
  EXPECT_EQ(cut, 1) << "the turned view cuts the grey ball";
}

// Without the listed diameters the grey ball's size relative to the chrome's is estimated.
TEST(BallIdentification, WithoutDiametersTheRigEstimatesTheBallsRelativeSize) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Views& r = rendered();
  const std::vector<ViewBalls> vb = with_true_rotations(r);
  const std::vector<ListedBall> listed = {{"chrome", BallKind::chrome, {}}, {"grey", BallKind::grey, {}}};
  const std::vector<RigMember> rig = fit_ball_rig(vb, listed);
  ASSERT_TRUE(rig[1].known);
  EXPECT_FALSE(rig[1].scale_given);
  EXPECT_NEAR(rig[1].scale, 1.0, 0.03);
}

// A ball given by hand is located at the guess; a guess too small to be one is an error.
TEST(BallIdentification, AGivenBallIsLocatedAtTheGuess) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Views& r = rendered();
  const Vec2 truth = testing::ball_centre_px(r.views[0], 1);
  const BallCandidate c = given_ball(r.views[0].radiance, r.scene.camera.lens, {truth + Vec2(2, -2), 25});
  EXPECT_LT((c.loc.centre_px - truth).norm(), 1.0);
  EXPECT_THROW(given_ball(r.views[0].radiance, r.scene.camera.lens, {truth, 0.5}), std::invalid_argument);
}

// Drawn balls (no renderer, quick): a mirror reflecting a patchwork of random brightness and a smoothly shaded
// sphere are told apart by appearance and matched to the listed kinds; a flat uniform disc (a
// Lambert fit cannot tell it from a ball in uniform light) twice their size is not taken for the
// grey ball: balls of one rig are at about the same distance.
TEST(BallIdentification, DrawnBallsAreMeasuredAndMatchedByAppearanceAndSize) {
  const LensModel lens = LensModel::pinhole(240, 240, 160);
  cv::Mat img(160, 240, CV_32FC3, cv::Scalar::all(0.3));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(0.05f, 2.0f);
  // The mirror's world: 15-degree cells of random brightness, all brighter than the background
  // (an outline all round), seen along r = 2 (n . v) n - v.
  std::uniform_real_distribution<float> bright(0.8f, 3.0f);
  std::vector<float> cells(24 * 12);
  for (float& c : cells) c = bright(rng);
  auto world = [&](const Vec3& r) {
    const double lon = std::atan2(r.x(), r.z()) + kPi, lat = std::acos(std::clamp(r.y(), -1.0, 1.0));
    return cells[std::size_t(std::min(11, int(lat / kPi * 12)) * 24 + std::min(23, int(lon / (2 * kPi) * 24)))];
  };
  auto draw = [&](const Vec2& c, double r, int kind) {
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) {
        const Vec2 d = (Vec2(x, y) - c) / r;
        if (d.squaredNorm() > 1) continue;
        const double nz = std::sqrt(1 - d.squaredNorm());
        const Vec3 n(d.x(), d.y(), nz);
        const float v = kind == 0   ? world(2 * nz * n - Vec3(0, 0, 1))
                        : kind == 1 ? float(0.2 - 0.12 * d.y() + 0.1 * nz)
                        : kind == 2 ? 0.8f
                                    : u(rng);
        img.at<cv::Vec3f>(y, x) = cv::Vec3f(v, v, v);
      }
  };
  draw(Vec2(50, 90), 20, 0);   // "chrome"
  draw(Vec2(120, 95), 21, 1);  // grey
  draw(Vec2(195, 60), 40, 2);  // a flat disc
  draw(Vec2(110, 32), 20, 3);  // a disc of noise (a printed pattern): textured, not compressed at its rim
  const std::vector<BallCandidate> c = find_ball_candidates(img, lens);
  ASSERT_GE(c.size(), 4u);
  const auto noise = std::find_if(c.begin(), c.end(),
                                  [](const BallCandidate& b) { return (b.loc.centre_px - Vec2(110, 32)).norm() < 2; });
  ASSERT_NE(noise, c.end());
  EXPECT_FALSE(looks_like(*noise, BallKind::chrome)) << "rim_radial " << noise->rim_radial;
  const std::vector<ListedBall> listed = {{"chrome", BallKind::chrome, 0.1}, {"grey", BallKind::grey, 0.1}};
  const std::vector<int> pick = assign_balls_in_view(c, listed);
  ASSERT_GE(pick[0], 0);
  ASSERT_GE(pick[1], 0);
  EXPECT_LT((c[std::size_t(pick[0])].loc.centre_px - Vec2(50, 90)).norm(), 1.5);
  EXPECT_LT((c[std::size_t(pick[1])].loc.centre_px - Vec2(120, 95)).norm(), 1.0);
  EXPECT_TRUE(looks_like(c[std::size_t(pick[0])], BallKind::chrome));
  EXPECT_TRUE(looks_like(c[std::size_t(pick[1])], BallKind::grey));
  EXPECT_FALSE(c[std::size_t(pick[1])].cut);
}

// The same mirror world drawn on a ball of 64 and of 256 pixels (its features scale with the ball):
// the rim texture, the chrome test's evidence, is the same, so a chrome ball photographed large in a
// phone frame is as chrome as one in a small crop.
TEST(BallIdentification, TheRimTextureDoesNotDependOnTheBallsSizeInPixels) {
  std::vector<double> rim;
  for (const double r : {64.0, 256.0}) {
    const int side = int(2.6 * r);
    const LensModel lens = LensModel::pinhole(100.0 * side, side, side);
    cv::Mat img(side, side, CV_32FC3, cv::Scalar::all(0.3));
    const Vec2 c(0.5 * (side - 1), 0.5 * (side - 1));
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) {
        const Vec2 d = (Vec2(x, y) - c) / r;
        if (d.squaredNorm() > 1) continue;
        // A world of bands a tenth of the radius wide, compressed toward the rim as a mirror shows it.
        const double s = d.norm(), phi = std::atan2(d.y(), d.x());
        const float v = float(std::exp(1.2 * std::sin(10 * kPi * s * s) * std::cos(7 * phi)));
        img.at<cv::Vec3f>(y, x) = cv::Vec3f(v, 0.9f * v, 0.8f * v);
      }
    const BallCandidate b = measure_ball(img, lens, locate_ball(img, lens, {c, r}));
    rim.push_back(b.rim_texture);
  }
  EXPECT_GT(rim[0], 0.25);  // a mirror by the chrome test
  EXPECT_NEAR(rim[1], rim[0], 0.1);
}

// A grey ball lit by a sun 50 times its sky, from the front, the side and behind (a lit crescent
// at the rim), with 2% pixel noise: its shading is one clamped cosine plus a smooth sky, which the
// Lambert fit holds within a few percent, leaving no texture; a mirror-like disc of the same size
// fits it by no means.
TEST(BallIdentification, AGreyBallLitByASunLooksGreyFromAnySide) {
  const LensModel lens = LensModel::pinhole(200, 160, 400);
  const Vec2 c(100, 80);
  const double r = 35;
  std::mt19937_64 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  std::uniform_real_distribution<float> u(0.05f, 2.0f);
  for (const Vec3& sun : {Vec3(0.3, -0.5, -0.8), Vec3(1, 0, 0), Vec3(-0.5, -0.3, 0.8), Vec3(0.1, 0.2, 1)}) {
    const Vec3 l = sun.normalized();  // camera frame: +z away from the camera, so z > 0 is behind the ball
    for (int kind = 0; kind < 2; ++kind) {
      cv::Mat img(160, 200, CV_32FC3, cv::Scalar::all(0.3));
      const BallCone cone{lens.unproject(c).normalized(), std::asin(1.0 / 10)};  // 10 radii away
      const Vec3 centre = cone.axis / std::sin(cone.half_angle);
      for (int y = 0; y < img.rows; ++y)
        for (int x = 0; x < img.cols; ++x) {
          const Vec3 d = lens.unproject(Vec2(x, y)).normalized();
          const double b = d.dot(centre), disc = b * b - (centre.squaredNorm() - 1);
          if (!(disc > 0)) continue;
          const Vec3 n = (b - std::sqrt(disc)) * d - centre;
          const double shade = 0.05 * (1.2 - 0.4 * n.y()) + 2.5 * std::max(0.0, n.dot(l));
          const float v = kind == 0 ? float(shade * (1 + noise(rng))) : u(rng);
          img.at<cv::Vec3f>(y, x) = cv::Vec3f(v, v, v);
        }
      BallLocation loc;
      loc.fit.cone = cone;
      loc.centre_px = lens.project(cone.axis);
      loc.radius_px = r;
      const BallCandidate m = measure_ball(img, lens, loc);
      if (kind == 0) {
        EXPECT_LT(m.diffuse_residual, 0.05) << "sun " << l.transpose();
        EXPECT_LT(m.shading_texture, 0.02) << "sun " << l.transpose();
        EXPECT_TRUE(looks_like(m, BallKind::grey)) << "sun " << l.transpose();
      } else {
        EXPECT_GT(m.diffuse_residual, 0.3);
        EXPECT_FALSE(looks_like(m, BallKind::grey));
      }
    }
  }
}

// A view whose chrome ball is not its anchor (no pose ball, no appearance test passed) gets one
// from the rig: placed from the grey ball where that is found, the true chrome ball within a
// tenth of its radius; a view without the grey ball gets none.
TEST(BallIdentification, TheRigPlacesAViewsChromeBallFromItsGreyBall) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Views& r = rendered();
  const std::vector<ViewBalls> vb = with_true_rotations(r);
  const std::vector<RigMember> rig = fit_ball_rig(vb, r.listed);
  ASSERT_TRUE(rig[1].known);
  int placed = 0;
  for (std::size_t i = 0; i < vb.size(); ++i) {
    ViewBalls v = vb[i];
    const bool had = v.chrome.has_value();
    EXPECT_FALSE(anchor_from_rig(v, rig, r.listed)) << "a view with an anchor keeps it";
    if (!had) continue;
    const BallCone truth = *v.chrome;
    v.chrome.reset();
    const std::optional<AnchorFromRig> a = anchor_from_rig(v, rig, r.listed);
    const Vec2 grey = testing::ball_centre_px(r.views[i], 1);
    const bool grey_seen = visible(r.views[i], 1) && r.scene.camera.lens.in_image(grey, -35);
    if (!a) {
      EXPECT_FALSE(grey_seen) << "view " << i;
      continue;
    }
    ++placed;
    EXPECT_EQ(a->placed_from, "grey");
    EXPECT_LT(angle_between(a->chrome.axis, truth.axis), 0.1 * truth.half_angle) << "view " << i;
    EXPECT_NEAR(a->chrome.half_angle, truth.half_angle, 0.1 * truth.half_angle) << "view " << i;
  }
  EXPECT_GE(placed, 3);
}

// The rig's geometry predicts a ball's cone from the chrome ball's: exact for the truth.
TEST(BallIdentification, ThePredictedConeOfATrueOffsetIsTheTrueCone) {
  const Mat3 world_from_cam = Eigen::AngleAxisd(0.3, Vec3(0.2, 1, 0.1).normalized()).toRotationMatrix();
  const Vec3 chrome_cam(0.1, -0.05, 1.2), grey_cam(0.25, -0.04, 1.25);  // metres
  const BallCone chrome{chrome_cam.normalized(), std::asin(0.05 / chrome_cam.norm())};
  const Vec3 offset = world_from_cam * (grey_cam - chrome_cam) / 0.05;
  const BallCone g = predicted_cone(chrome, world_from_cam, offset, 0.8);  // a 4 cm grey ball
  EXPECT_LT(angle_between(g.axis, grey_cam), 1e-12);
  EXPECT_NEAR(std::sin(g.half_angle), 0.04 / grey_cam.norm(), 1e-12);
}

// rig_suspects: a view is suspect beyond max(0.25 chrome radii, 4 x the checked views' median);
// unchecked views (< 0) never are; with fewer than 3 checked views nothing is judged; a rig that
// every view fits loosely (a high median) leaves every view in.
TEST(BallIdentification, RigSuspectsAreTheViewsFarBeyondTheMedianDisagreement) {
  const RigSuspects s = rig_suspects({0.05, 0.61, 0.06, 0.44, 0.07, 0.04, 0.08, 0.05, -1.0});
  EXPECT_DOUBLE_EQ(s.median, 0.07);  // of the 8 checked: the upper middle value
  EXPECT_DOUBLE_EQ(s.limit, 4 * 0.07);
  EXPECT_EQ(s.suspect, (std::vector<char>{0, 1, 0, 1, 0, 0, 0, 0, 0}));
  const RigSuspects at_limit = rig_suspects({0.25, 0.05, 0.05, 0.05, 0.05, 0.2501});
  EXPECT_DOUBLE_EQ(at_limit.limit, 0.25);
  EXPECT_EQ(at_limit.suspect, (std::vector<char>{0, 0, 0, 0, 0, 1}));
  const RigSuspects loose = rig_suspects({0.3, 0.35, 0.32, 1.3, 1.5});
  EXPECT_DOUBLE_EQ(loose.limit, 4 * 0.35);
  EXPECT_EQ(loose.suspect, (std::vector<char>{0, 0, 0, 0, 1}));
  const RigSuspects few = rig_suspects({0.05, 3.0, -1.0, -1.0});
  EXPECT_LT(few.median, 0);
  EXPECT_EQ(few.suspect, (std::vector<char>{0, 0, 0, 0}));
  RigSuspectOptions strict;
  strict.radii = 0.1;
  strict.median_factor = 1;
  EXPECT_EQ(rig_suspects({0.05, 0.11, 0.06, 0.07}, strict).suspect, (std::vector<char>{0, 1, 0, 0}));
}

}  // namespace
}  // namespace rsibr
