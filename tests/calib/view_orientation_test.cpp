// calib/orientation/view_orientation.h: images in, poses out. Four rendered views of a chrome ball in a real
// environment (CC0 `lobby`, cache/) are oriented without any truth given (the balls detected, the
// gauge by the up direction), and compared with the renderer's poses; one view, no ball and two
// views sharing nothing give one clear error.
#include "calib/orientation/view_orientation.h"

#include "calib_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

namespace rsibr {
namespace {

using testing::kLobby;
using testing::median;
const std::filesystem::path kPark = std::filesystem::path(RSIBR_CACHE_DIR) / "assets/hdri/park.exr";

struct Rendered {
  LensModel lens;
  std::vector<ViewImage> views;
  std::vector<Mat3> truth;
  std::vector<std::string> names;
  std::vector<Vec2> centre_px;     // the chrome ball's true centre pixel
  std::vector<double> half_angle;  // and its true angular radius, radians
};

// Views at the given azimuths around a chrome ball of radius_px (the grey ball beside it, off the
// image; none with `chrome_only`, as views 90 degrees around would see it in line with the chrome
// ball), noise 1%.
Rendered render(const std::filesystem::path& env, const std::vector<double>& azimuths, double radius_px = 120,
                bool chrome_only = false) {
  const double distance = 0.5, f = radius_px * distance / 0.05;
  SynthScene scene =
      testing::rig_scene(LensModel::pinhole(f, int(2.5 * radius_px), int(2.3 * radius_px)), distance, false);
  if (chrome_only) scene.balls.resize(1);
  scene.environment.file = env;
  scene.environment.sanitize = true;
  scene.views.front().azimuths_deg = azimuths;
  scene.views.front().roll_deg = 7;
  scene.views.front().look_at = scene.balls.front().centre;
  Rendered r{scene.camera.lens, {}, {}, {}, {}, {}};
  for (std::size_t v = 0; v < azimuths.size(); ++v) {
    const auto view = testing::render_view(scene, static_cast<int>(v), 0.01, 5 + v);
    ViewImage vi;
    vi.radiance = view.radiance;
    r.views.push_back(vi);
    r.truth.push_back(view.pose.world_from_cam);
    r.names.push_back("v" + std::to_string(v));
    r.centre_px.push_back(testing::ball_centre_px(view, 0));
    r.half_angle.push_back(std::asin(0.5 * scene.balls.front().diameter_m / testing::ball_centre_cam(view, 0).norm()));
  }
  return r;
}

double angle_deg(const Mat3& a, const Mat3& b) { return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / kPi; }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ViewOrientation, UpGaugeMapsTheGivenUpToWorldYAndTheFirstForwardToTheHorizon) {
  const Vec3 up = Vec3(0.1, -0.9, 0.2).normalized();
  const Mat3 r = gauge_world_from_first_cam(up);
  EXPECT_LT((r * up - Vec3(0, 1, 0)).norm(), 1e-12);
  EXPECT_LT((r.transpose() * r - Mat3::Identity()).norm(), 1e-12);
  EXPECT_NEAR(r.determinant(), 1, 1e-12);
  const Vec3 fwd = r * Vec3(0, 0, 1);  // the first camera's forward in the world: in the +Z half of the Y-Z plane
  EXPECT_NEAR(fwd.x(), 0, 1e-12);
  EXPECT_GT(fwd.z(), 0);
  // Straight down: still a rotation, +Y = up.
  const Mat3 d = gauge_world_from_first_cam(Vec3(0, 0, -1));
  EXPECT_LT((d * Vec3(0, 0, -1) - Vec3(0, 1, 0)).norm(), 1e-12);
  EXPECT_NEAR(d.determinant(), 1, 1e-12);
  EXPECT_TRUE(gauge_world_from_first_cam(std::nullopt).isIdentity());
  EXPECT_THROW(gauge_world_from_first_cam(Vec3::Zero()), std::invalid_argument);
}

TEST(ViewOrientation, RenderedViewsAreRecoveredUpToTheGaugeWithDetectedBalls) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Rendered r = render(kLobby, {0, 20, 40, 60});
  ViewOrientationOptions o;
  o.up = r.truth[0].transpose() * Vec3(0, 1, 0);  // the world's up in the first camera's frame, as a level would give
  ViewOrientationReport rep;
  const PoseSet p = orient_views(r.names, r.views, r.lens, o, &rep);
  ASSERT_EQ(p.views.size(), 4u);
  EXPECT_EQ(p.gauge, "up");
  // The recovered world differs from the truth's by a rotation about +Y only (the gauge's yaw).
  const Mat3 g = p.views[0].world_from_cam * r.truth[0].transpose();
  EXPECT_LT((g * Vec3(0, 1, 0) - Vec3(0, 1, 0)).norm(), 1e-9);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(p.views[v].name, r.names[v]);
    const double e = angle_deg(p.views[v].world_from_cam, g * r.truth[v]);
    std::printf(
        "  view %d: ball (%.2f, %.2f) [truth (%.2f, %.2f)] r %.2f, %d features, error %.3f deg, sigma %.3f deg\n", v,
        rep.balls[v].centre_px.x(), rep.balls[v].centre_px.y(), r.centre_px[v].x(), r.centre_px[v].y(),
        rep.balls[v].radius_px, rep.features[v], e, p.views[v].sigma_deg);
    // The ball located from the image alone is off by ~0.5-3 px on this textured background, ~1
    // degree per pixel on a 120-px ball; refined with the re-located tracks it comes within 0.05 px
    // and the errors to 0.02-0.06 degrees (0.2-0.5 with SIFT's keypoints as they are). Guarded at
    // 0.2 degrees and 0.2 px; a wrong ball or frame gives tens.
    EXPECT_LT(e, 0.2);
    EXPECT_LT((rep.balls[v].centre_px - r.centre_px[v]).norm(), 0.2);
    EXPECT_TRUE(std::isfinite(p.views[v].sigma_deg));
    if (v > 0) {
      EXPECT_GT(p.views[v].sigma_deg, 0);
    }
  }
  EXPECT_EQ(p.views[0].sigma_deg, 0);
  // The sigmas include the ball centres' uncertainty: the errors are within a few sigmas (mean
  // (error/sigma)^2 below 10; with the centres held fixed it is 25-60 on these views).
  double chi2 = 0;
  for (int v = 1; v < 4; ++v)
    chi2 += std::pow(angle_deg(p.views[v].world_from_cam, g * r.truth[v]) / p.views[v].sigma_deg, 2) / 3;
  std::printf("  mean (error/sigma)^2 = %.2f\n", chi2);
  EXPECT_LT(chi2, 10.0);
}

// poses.yaml carries each view's chrome ball as refined with the orientations; extraction takes it
// for the located ball it describes (centre within half a radius) and keeps the outline's otherwise.
TEST(ViewOrientation, ExtractionTakesThePoseFilesRefinedBallOnlyForTheSameBall) {
  const LensModel lens = LensModel::pinhole(1000, 640, 480);
  BallLocation loc;
  loc.fit.cone.axis = lens.unproject(Vec2(320, 240)).normalized();
  loc.fit.cone.half_angle = 0.1;
  loc.centre_px = Vec2(320, 240);
  loc.radius_px = 100;
  ViewPose pose;
  EXPECT_EQ(extraction_cone(loc, pose, lens).half_angle, 0.1);  // no ball in the pose file
  BallCone refined;
  refined.axis = lens.unproject(Vec2(320.3, 239.8)).normalized();
  refined.half_angle = 0.1008;
  pose.ball = refined;
  EXPECT_EQ(extraction_cone(loc, pose, lens).half_angle, 0.1008);
  EXPECT_EQ(extraction_cone(loc, pose, lens).axis, refined.axis);
  pose.ball->axis = lens.unproject(Vec2(480, 240)).normalized();  // another ball (the grey one beside it)
  EXPECT_EQ(extraction_cone(loc, pose, lens).half_angle, 0.1);
}

// The accuracy target on a realistic capture: eight views 45 degrees apart around a 400-px chrome
// ball (an 800-px disc, a light probe's size in a photograph), 1% noise, nothing given but the lens
// and the first view's up. The outline alone puts the centre ~0.1-3 px off and the radius 0.3-2 px
// inside the limb; refined with the features (SIFT's keypoints re-located by patch alignment,
// calib/orientation/track_refinement.h), centres and radii come within hundredths of a pixel and the
// orientations within a hundredth of a degree. Guarded at half of 0.05 degrees.
// Centre, radius and orientation are each checked against the renderer's truth.
TEST(ViewOrientation, ARingOfViewsAroundALightProbeSizedBallIsOrientedToAHundredthOfADegreeAndHundredthsOfAPixel) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  std::vector<double> azimuths;
  for (int v = 0; v < 8; ++v) azimuths.push_back(45.0 * v);
  const double radius_px = 400;
  const Rendered r = render(kLobby, azimuths, radius_px, true);
  ViewOrientationOptions o;
  o.up = r.truth[0].transpose() * Vec3(0, 1, 0);
  ViewOrientationReport rep;
  const PoseSet p = orient_views(r.names, r.views, r.lens, o, &rep);
  const Mat3 g = p.views[0].world_from_cam * r.truth[0].transpose();
  std::vector<double> errors, centres;
  double chi2 = 0, radius_error = 0;
  const double f = radius_px * 0.5 / 0.05;  // render()'s focal length
  for (std::size_t v = 0; v < azimuths.size(); ++v) {
    centres.push_back((rep.balls[v].centre_px - r.centre_px[v]).norm());
    const double a = r.half_angle[v];
    radius_error =
        std::max(radius_error, std::abs(rep.balls[v].fit.cone.half_angle - a) * f / (std::cos(a) * std::cos(a)));
    if (v == 0) continue;
    errors.push_back(angle_deg(p.views[v].world_from_cam, g * r.truth[v]));
    chi2 += std::pow(errors.back() / p.views[v].sigma_deg, 2) / double(azimuths.size() - 1);
  }
  std::printf(
      "  %d tracks; orientation error median %.4f, max %.4f deg; mean (error/sigma)^2 %.2f; centre error median %.3f, "
      "max %.3f px; radius error max %.3f px\n",
      rep.tracks, median(errors), *std::max_element(errors.begin(), errors.end()), chi2, median(centres),
      *std::max_element(centres.begin(), centres.end()), radius_error);
  EXPECT_LE(median(errors), 0.025);
  EXPECT_LT(*std::max_element(errors.begin(), errors.end()), 0.05);
  // Honest sigmas: the mean of 7 (error/sigma)^2, each ~ chi2_3 / 3 when honest (chi2_21 / 21), lies
  // in [0.38, 1.97] with 99% probability; guarded at [0.3, 2.5].
  EXPECT_GT(chi2, 0.3);
  EXPECT_LT(chi2, 2.5);
  EXPECT_LE(median(centres), 0.05);
  EXPECT_LT(*std::max_element(centres.begin(), centres.end()), 0.1);
  EXPECT_LT(radius_error, 0.05);
}

// Wide baselines: a world feature seen near the ball's centre in one view is near the rim,
// compressed up to ~10x radially, in the other. On the cube faces (calib/orientation/ball_cube_features.h) it
// looks the same in both. Measured (park, 120-px ball, noise 1%): 110-146 tracks, errors 0.33-0.47
// degrees with SIFT's keypoints (4 seeds), 0.11 and 0.14 with the tracks re-located (this seed);
// SIFT in the image itself finds 12-20 tracks here and fails at 60 px radius.
TEST(ViewOrientation, ViewsSixtyAndNinetyDegreesApartAreOrientedOnTheCubeFaces) {
  if (!std::filesystem::exists(kPark)) GTEST_SKIP() << kPark << " missing (scripts/fetch-assets.sh)";
  const Rendered r = render(kPark, {0, 60, 90}, 120, true);
  double chi2 = 0;
  for (int v : {1, 2}) {
    ViewOrientationOptions o;
    o.up = r.truth[0].transpose() * Vec3(0, 1, 0);
    ViewOrientationReport rep, img_rep;
    const PoseSet p = orient_views({r.names[0], r.names[v]}, {r.views[0], r.views[v]}, r.lens, o, &rep);
    const Mat3 g = p.views[0].world_from_cam * r.truth[0].transpose();
    const double e = angle_deg(p.views[1].world_from_cam, g * r.truth[v]);
    // The two front ends on the same views without the rotation search, for the track count.
    o.search_rotations = false;
    ViewOrientationReport cube_rep;
    orient_views({r.names[0], r.names[v]}, {r.views[0], r.views[v]}, r.lens, o, &cube_rep);
    o.domain = FeatureDomain::image;
    int img_tracks = 0;
    try {
      orient_views({r.names[0], r.names[v]}, {r.views[0], r.views[v]}, r.lens, o, &img_rep);
      img_tracks = img_rep.tracks;
    } catch (const std::invalid_argument&) {
    }
    std::printf(
        "  %s degrees apart: %d tracks (without the search: %d, image domain %d), error %.3f deg, sigma %.3f deg\n",
        v == 1 ? "60" : "90", rep.tracks, cube_rep.tracks, img_tracks, e, p.views[1].sigma_deg);
    EXPECT_LT(e, 1.0);
    ASSERT_GT(p.views[1].sigma_deg, 0);
    EXPECT_GE(cube_rep.tracks, 4 * std::max(img_tracks, 10));
    EXPECT_GE(rep.tracks, cube_rep.tracks);  // the search serves only views these leave unplaced
    chi2 += std::pow(e / p.views[1].sigma_deg, 2) / 2;
  }
  // Honest sigmas: the mean of two (error/sigma)^2, each ~ chi2_3 / 3 when honest, lies in [0.11, 2.8]
  // with 99% probability; guarded at [0.05, 4].
  std::printf("  mean (error/sigma)^2 = %.2f\n", chi2);
  EXPECT_GT(chi2, 0.05);
  EXPECT_LT(chi2, 4.0);
}

// An interior shot from two rings (six views level, six 40 degrees above, between them): views
// 60 degrees apart on a ring and 40-50 degrees across rings. Every view is oriented, within half a
// degree of the truth; the error against the stated sigma is printed.
TEST(ViewOrientation, TwelveViewsOnTwoRingsOfAnInteriorAreAllOrientedWithinHalfADegree) {
  const std::filesystem::path interior = std::filesystem::path(RSIBR_CACHE_DIR) / "assets/hdri/apartment.exr";
  if (!std::filesystem::exists(interior)) GTEST_SKIP() << interior << " missing (scripts/fetch-assets.sh)";
  const double radius_px = 120, distance = 0.5, f = radius_px * distance / 0.05;
  SynthScene scene =
      testing::rig_scene(LensModel::pinhole(f, int(2.5 * radius_px), int(2.3 * radius_px)), distance, false);
  scene.balls.resize(1);
  scene.environment.file = interior;
  scene.environment.sanitize = true;
  SynthViewPlan level = scene.views.front();
  level.count = 6, level.elevation_deg = 0, level.roll_deg = 4, level.look_at = scene.balls.front().centre;
  SynthViewPlan high = level;
  high.elevation_deg = 40, high.azimuth0_deg = 30;
  scene.views = {level, high};
  std::vector<std::string> names;
  std::vector<ViewImage> views;
  std::vector<Mat3> truth;
  for (int v = 0; v < 12; ++v) {
    const auto view = testing::render_view(scene, v, 0.01, 11 + v);
    ViewImage vi;
    vi.radiance = view.radiance;
    views.push_back(vi);
    truth.push_back(view.pose.world_from_cam);
    names.push_back("v" + std::to_string(v));
  }
  ViewOrientationOptions o;
  o.up = truth[0].transpose() * Vec3(0, 1, 0);
  ViewOrientationReport rep;
  const PoseSet p = orient_views(names, views, scene.camera.lens, o, &rep);
  ASSERT_EQ(p.views.size(), 12u) << (rep.left_out.empty() ? "" : rep.left_out.front());
  const Mat3 g = p.views[0].world_from_cam * truth[0].transpose();
  double worst = 0, chi2 = 0;
  for (std::size_t v = 1; v < 12; ++v) {
    const double e = angle_deg(p.views[v].world_from_cam, g * truth[v]);
    worst = std::max(worst, e / p.views[v].sigma_deg);
    chi2 += std::pow(e / p.views[v].sigma_deg, 2) / 11;
    EXPECT_LT(e, 0.5) << names[v] << ": error " << e << " deg, sigma " << p.views[v].sigma_deg;
  }
  std::vector<double> errs;
  for (std::size_t v = 1; v < 12; ++v) errs.push_back(angle_deg(p.views[v].world_from_cam, g * truth[v]));
  std::printf(
      "  12 views on two rings: %d tracks, largest error / sigma %.2f, mean (error / sigma)^2 %.2f, median error %.3f max %.3f\n",
      rep.tracks, worst, chi2, testing::median(errs), *std::max_element(errs.begin(), errs.end()));
}

// The agreement of two views (calib/orientation/view_agreement.h) at their true rotations and balls: a view
// exposed twice as long shows the offset as -1 stop exactly; the mismatch is small at the truth
// and grows when the second view is turned 5 degrees.
TEST(ViewOrientation, TwoViewsAgreeAtTheTruthWithTheirExposureOffsetAndDisagreeWhenTurned) {
  if (!std::filesystem::exists(kPark)) GTEST_SKIP() << kPark << " missing (scripts/fetch-assets.sh)";
  const Rendered r = render(kPark, {0, 70}, 120, true);
  std::vector<BallCone> cones;
  for (int v = 0; v < 2; ++v)
    cones.push_back({r.lens.unproject(r.centre_px[std::size_t(v)]).normalized(), r.half_angle[std::size_t(v)]});
  ViewImage brighter = r.views[1];
  brighter.radiance = r.views[1].radiance * 2;
  const ViewAgreement at = view_agreement(r.views[0], cones[0], r.truth[0], brighter, cones[1], r.truth[1], r.lens);
  EXPECT_GT(at.overlap, 0.2);
  EXPECT_NEAR(at.median_log2_ratio, -1, 0.02);
  const Mat3 turned = r.truth[1] * Eigen::AngleAxisd(5 * kPi / 180, Vec3(1, 2, 0).normalized()).toRotationMatrix();
  const ViewAgreement off = view_agreement(r.views[0], cones[0], r.truth[0], brighter, cones[1], turned, r.lens);
  std::printf("  mismatch %.3f stops at the truth, %.3f turned 5 degrees\n", at.mismatch_stops, off.mismatch_stops);
  EXPECT_GT(off.mismatch_stops, 1.5 * at.mismatch_stops);
  // Nothing in common: no samples, no NaN.
  const Mat3 away = r.truth[0] * Eigen::AngleAxisd(kPi, Vec3(0, 1, 0)).toRotationMatrix();
  AgreementOptions narrow;
  narrow.max_radius_fraction = 0.3;  // each sees a small cap around its camera
  const ViewAgreement none =
      view_agreement(r.views[0], cones[0], r.truth[0], r.views[0], cones[0], away, r.lens, narrow);
  EXPECT_EQ(none.samples, 0);
  EXPECT_EQ(none.overlap, 0);
}

// The manual fallback: ten points "picked" where two views' balls show the same world directions
// (their true pixels plus 0.5 px of noise), solved without any feature, give the rotation the
// features give, within the two stated sigmas; a point off the ball is one error naming it.
TEST(ViewOrientation, PointsPickedByHandAloneReproduceTheFeatureRotationWithinTheirSigmas) {
  if (!std::filesystem::exists(kPark)) GTEST_SKIP() << kPark << " missing (scripts/fetch-assets.sh)";
  const Rendered r = render(kPark, {0, 70}, 120, true);
  ViewOrientationOptions o;
  o.up = r.truth[0].transpose() * Vec3(0, 1, 0);
  const PoseSet automatic = orient_views({r.names[0], r.names[1]}, {r.views[0], r.views[1]}, r.lens, o);
  // Picked points: world directions both balls show well inside their rims.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.5);
  BallFeatureOptions inner;
  inner.max_radius_fraction = 0.8;
  PointPairs pp;
  pp.sigma_px = 0.5;
  for (int tries = 0; tries < 10000 && pp.points.size() < 10; ++tries) {
    const Vec3 d = Vec3(noise(rng), noise(rng), noise(rng)).normalized();
    PickedPoint p;
    p.where = "test: points[" + std::to_string(pp.points.size()) + "]";
    for (int v = 0; v < 2; ++v) {
      const BallCone cone{r.lens.unproject(r.centre_px[std::size_t(v)]).normalized(), r.half_angle[std::size_t(v)]};
      const auto px = ball_pixel_of(r.lens, cone, inner, r.truth[std::size_t(v)].transpose() * d, false);
      if (px) p.seen.push_back({r.names[std::size_t(v)], px->pixel + Vec2(noise(rng), noise(rng))});
    }
    if (p.seen.size() == 2) pp.points.push_back(p);
  }
  ASSERT_EQ(pp.points.size(), 10u);
  o.points = pp;
  o.match_features = false;
  o.search_rotations = false;
  const PoseSet picked = orient_views({r.names[0], r.names[1]}, {r.views[0], r.views[1]}, r.lens, o);
  const double sa = automatic.views[1].sigma_deg, sp = picked.views[1].sigma_deg;
  const double apart = angle_deg(automatic.views[1].world_from_cam, picked.views[1].world_from_cam);
  const Mat3 g = picked.views[0].world_from_cam * r.truth[0].transpose();
  const double err = angle_deg(picked.views[1].world_from_cam, g * r.truth[1]);
  std::printf("  picked points: error %.3f deg, sigma %.3f deg; %.3f deg from the features' (sigma %.3f deg)\n", err,
              sp, apart, sa);
  EXPECT_GT(sp, sa);  // ten points against hundreds of features
  EXPECT_LT(err, 3 * sp);
  EXPECT_LT(apart, 3 * std::hypot(sa, sp));
  // A point off the ball.
  o.points.points[3].seen[1].second = Vec2(2, 2);
  const std::string e = error_of([&] { orient_views({r.names[0], r.names[1]}, {r.views[0], r.views[1]}, r.lens, o); });
  EXPECT_NE(e.find("test: points[3].v1: (2.0, 2.0) is not on the chrome ball"), std::string::npos) << e;
}

// The grey ball beside the chrome one often has the cleaner outline (more inlier outline points):
// the chrome ball is chosen by its texture, and neither a straight edge's huge circle nor a circle
// reflected inside the chrome ball is taken for a ball.
TEST(ViewOrientation, TheChromeBallIsChosenOverTheGreyBallBesideIt) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const double radius_px = 60, distance = 0.5, f = radius_px * distance / 0.05;
  SynthScene scene = testing::rig_scene(LensModel::pinhole(f, 520, 150), distance, false);
  scene.environment.file = kLobby;
  scene.environment.sanitize = true;
  scene.views.front().azimuths_deg = {0, 20};
  scene.views.front().look_at = Vec3(0, 1.3, 0);  // both balls in the image
  std::vector<ViewImage> views;
  std::vector<Vec2> chrome, grey;
  for (int v = 0; v < 2; ++v) {
    const auto view = testing::render_view(scene, v, 0.01, 5 + v);
    ViewImage vi;
    vi.radiance = view.radiance;
    views.push_back(vi);
    chrome.push_back(testing::ball_centre_px(view, 0));
    grey.push_back(testing::ball_centre_px(view, 1));
    ASSERT_TRUE(scene.camera.lens.in_image(grey.back(), radius_px)) << grey.back().transpose();
  }
  ViewOrientationReport rep;
  orient_views({"a", "b"}, views, scene.camera.lens, {}, &rep);
  for (int v = 0; v < 2; ++v) {
    std::printf("  view %d: ball (%.1f, %.1f), chrome (%.1f, %.1f), grey (%.1f, %.1f)\n", v, rep.balls[v].centre_px.x(),
                rep.balls[v].centre_px.y(), chrome[v].x(), chrome[v].y(), grey[v].x(), grey[v].y());
    EXPECT_LT((rep.balls[v].centre_px - chrome[v]).norm(), 3.0);
  }
}

TEST(ViewOrientation, OneViewIsAShootAndNoBallOrNothingSharedGiveOneClearError) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const Rendered r = render(kLobby, {0}, 60);
  // One view: its camera is the world frame (levelled by the estimated up), its ball as located.
  ViewOrientationReport rep;
  const PoseSet one = orient_views({"only"}, {r.views[0]}, r.lens, {}, &rep);
  ASSERT_EQ(one.views.size(), 1u);
  const Mat3& R = one.views[0].world_from_cam;
  EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-9);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
  EXPECT_TRUE(one.views[0].ball.has_value());
  // No ball: a featureless flat image.
  ViewImage flat;
  flat.radiance = cv::Mat(r.views[0].radiance.size(), CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  EXPECT_NE(error_of([&] {
              orient_views({"flat"}, {flat}, r.lens);
            }).find("found in 0 of 1 views, need at least 1 (flat: no chrome ball"),
            std::string::npos);
  // (A view without a chrome ball is left out; with fewer than 2 left, one line names it.)
  EXPECT_NE(error_of([&] {
              orient_views({"a", "empty"}, {r.views[0], flat}, r.lens);
            }).find("empty: no chrome ball found"),
            std::string::npos);
  // Two views of different worlds share no feature.
  const std::filesystem::path other = std::filesystem::path(RSIBR_CACHE_DIR) / "assets/hdri/forest.exr";
  if (!std::filesystem::exists(other)) GTEST_SKIP() << other << " missing";
  const Rendered s = render(other, {20}, 60);
  const std::string e = error_of([&] { orient_views({"lobby", "forest"}, {r.views[0], s.views[0]}, r.lens); });
  EXPECT_EQ(e.rfind("orient: only 1 view(s) could be oriented (forest: ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

}  // namespace
}  // namespace rsibr
