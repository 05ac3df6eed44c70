// World up from the views (calib/orientation/world_up.h): the direction most perpendicular to every camera's x
// axis. Cameras from capture/'s view plans (handheld rings aimed down at the rig, jittered like a
// hand), expressed in the first camera's frame as the orientation solve's first-view gauge leaves them.
#include "calib/orientation/view_orientation.h"
#include "calib/orientation/world_up.h"

#include "capture/camera_poses.h"
#include "capture/synth_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace rsibr {
namespace {

SynthScene handheld(int count, double elevation_deg, double jitter_deg, std::uint64_t seed, double jitter_m = 0.02) {
  const std::string text = "rsibr_synth: 1\nseed: " + std::to_string(seed) + R"(
environment: {pattern: sun_and_sky}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}
camera: {width: 64, height: 48, lens: {model: LENSMODEL_PINHOLE, focal_px: 100}}
views:
  - {plan: handheld, count: )" +
                           std::to_string(count) + ", elevation_deg: " + std::to_string(elevation_deg) +
                           ", distance_m: 0.6, jitter_m: " + std::to_string(jitter_m) +
                           ", jitter_deg: " + std::to_string(jitter_deg) + "}\n";
  return parse_synth_scene(text, "handheld.yaml", ".");
}

// The cameras in the first camera's frame, and the true up there.
std::vector<Mat3> in_first_camera(const std::vector<CameraPose>& poses, Vec3* up) {
  const Mat3 first_from_world = poses.front().world_from_cam.transpose();
  std::vector<Mat3> out;
  for (const CameraPose& p : poses) out.push_back(first_from_world * p.world_from_cam);
  *up = first_from_world * Vec3(0, 1, 0);
  return out;
}

TEST(WorldUp, LevelCamerasGiveTheExactUpWhateverTheyAimAt) {
  for (double elevation : {0.0, 20.0, 45.0}) {
    Vec3 up;
    const std::vector<Mat3> r = in_first_camera(plan_camera_poses(handheld(6, elevation, 0.0, 1, 0.0)), &up);
    const WorldUp w = estimate_world_up(r);
    // Exact but for the upright prior's pull (20 degrees against rolls known to 0.2 degrees).
    EXPECT_LT(angle_between(w.up, up) / kDeg, 1e-3) << elevation;
    EXPECT_NEAR(w.tilt_from_first_deg, elevation, 1e-3) << "the first camera is aimed down by its elevation";
    for (double roll : w.roll_deg) EXPECT_LT(std::abs(roll), 1e-3);
  }
}

// Handheld rings aimed 10-30 degrees down, jittered by 1.5 degrees (std dev, any axis): the probe's
// horizon level within 1 degree (the first camera's up would tilt it by the elevation), and the
// error within 3 of the reported sigmas.
TEST(WorldUp, HandheldRingsAimedDownAreLevelWithinADegree) {
  int n = 0;
  for (std::uint64_t seed : {1, 2, 3, 4, 5, 6})
    for (double elevation : {10.0, 22.0, 30.0}) {
      Vec3 up;
      const std::vector<Mat3> r = in_first_camera(plan_camera_poses(handheld(8, elevation, 1.5, seed)), &up);
      const WorldUp w = estimate_world_up(r);
      const double err = angle_between(w.up, up) / kDeg;
      EXPECT_LT(err, 1.0) << "seed " << seed << ", elevation " << elevation;
      EXPECT_LT(err, 3 * w.sigma_deg + 0.05) << "seed " << seed << ", elevation " << elevation;
      EXPECT_GT(angle_between(-r.front().col(1), up) / kDeg, elevation - 5) << "the naive gauge is off";
      EXPECT_TRUE(w.roll_sigma_estimated);
      EXPECT_GT(w.roll_sigma_deg, 0.3);
      EXPECT_LT(w.roll_sigma_deg, 2.5);
      ++n;
    }
  EXPECT_EQ(n, 18);
}

// Two of ten cameras turned about their own tilted axis (their x 5 degrees out of the horizontal)
// do not pull the level of the other eight: they are weighted down and their rolls reported.
TEST(WorldUp, CamerasRolledOutOfLevelAreWeightedDown) {
  for (std::uint64_t seed : {1, 2, 3}) {
    Vec3 up;
    std::vector<CameraPose> poses = plan_camera_poses(handheld(10, 25, 0.5, seed));
    for (int k : {3, 7})
      poses[std::size_t(k)].world_from_cam =
          poses[std::size_t(k)].world_from_cam * Eigen::AngleAxisd(5 * kDeg, Vec3::UnitZ()).toRotationMatrix();
    const std::vector<Mat3> r = in_first_camera(poses, &up);
    const WorldUp w = estimate_world_up(r);
    EXPECT_LT(angle_between(w.up, up) / kDeg, 0.35) << seed;
    EXPECT_GT(std::abs(w.roll_deg[3]), 4.0);
    EXPECT_GT(std::abs(w.roll_deg[7]), 4.0);
  }
}

// The sigma follows the cameras' roll scatter: 3 degrees of jitter give a larger one than 0.5.
TEST(WorldUp, UncertaintyGrowsWithTheRollScatter) {
  Vec3 up;
  const WorldUp small = estimate_world_up(in_first_camera(plan_camera_poses(handheld(8, 20, 0.5, 3)), &up));
  const WorldUp large = estimate_world_up(in_first_camera(plan_camera_poses(handheld(8, 20, 3.0, 3)), &up));
  EXPECT_LT(small.sigma_deg, large.sigma_deg);
  EXPECT_GT(large.roll_sigma_deg, 2 * small.roll_sigma_deg);
}

// Three cameras looking along -Z, aimed 15 degrees down, 2 degrees apart in azimuth.
std::vector<Mat3> from_one_side() {
  std::vector<Mat3> r;
  for (double yaw : {-2.0, 0.0, 2.0})
    r.push_back(Eigen::AngleAxisd(yaw * kDeg, Vec3::UnitY()).toRotationMatrix() *
                Eigen::AngleAxisd(-15 * kDeg, Vec3::UnitX()).toRotationMatrix() *
                (Mat3() << 1, 0, 0, 0, -1, 0, 0, 0, -1).finished());
  return r;
}

// Cameras all on one side (x axes parallel) cannot fix the tilt about that axis: the upright prior
// (the cameras' mean -y) decides it, and the sigma says so.
TEST(WorldUp, ViewsFromOneSideFallBackToTheUprightPriorAndSayItIsUncertain) {
  const std::vector<Mat3> r = from_one_side();
  const WorldUp w = estimate_world_up(r);
  EXPECT_TRUE(w.up.allFinite());
  EXPECT_GT(w.sigma_deg, 5.0);
  EXPECT_GT(w.up.y(), 0.9);
}

// A vertical line (the stand) fixes up where the rolls cannot; its plane normals are exact here.
TEST(WorldUp, AVerticalLineAddsWhatTheRollsCannotFix) {
  const std::vector<Mat3> r = from_one_side();
  // A plane containing +Y seen by the views: normal (0, 0, 1) (the line through the ball, in x = 0).
  const WorldUp w = estimate_world_up(r, {{Vec3(0, 0, 1), 0.2, "stand"}});
  EXPECT_LT(angle_between(w.up, Vec3(0, 1, 0)) / kDeg, 0.01);
  EXPECT_LT(w.sigma_deg, 1.0);
  EXPECT_EQ(w.lines, 1);
}

// A line that is not vertical (a leaning pole, a wall's edge taken for the stand) gives way: four
// vertical lines and one 8 degrees off, all claiming 0.2 degrees, leave up within the cameras' own
// level (an unweighted line would pull it several degrees toward itself).
TEST(WorldUp, ALineThatIsNotVerticalGivesWay) {
  for (std::uint64_t seed : {4, 5, 6}) {
    Vec3 up;
    const std::vector<Mat3> r = in_first_camera(plan_camera_poses(handheld(10, 25, 0.5, seed)), &up);
    std::vector<VerticalLine> lines;
    for (double az : {0.0, 40.0, 95.0, 150.0})
      lines.push_back({Eigen::AngleAxisd(az * kDeg, up).toRotationMatrix() * up.unitOrthogonal(), 0.2, "stand"});
    const Vec3 n = Eigen::AngleAxisd(70 * kDeg, up).toRotationMatrix() * up.unitOrthogonal();
    lines.push_back({(std::cos(8 * kDeg) * n + std::sin(8 * kDeg) * up).normalized(), 0.2, "leaning"});
    const WorldUp w = estimate_world_up(r, lines);
    std::printf("  seed %d: up %.3f degrees off\n", int(seed), angle_between(w.up, up) / kDeg);
    EXPECT_LT(angle_between(w.up, up) / kDeg, 0.3) << seed;
    EXPECT_TRUE(w.up.allFinite());
  }
}

TEST(WorldUp, NoCamerasOrANonFiniteRotationAreErrors) {
  EXPECT_THROW(estimate_world_up({}), std::invalid_argument);
  Mat3 bad = Mat3::Identity();
  bad(0, 0) = NAN;
  EXPECT_THROW(estimate_world_up({bad}), std::invalid_argument);
}

// level_pose_set turns a first-view pose set into the estimated-up gauge: +Y is the true up.
TEST(WorldUp, LevellingAPoseSetPutsTheEstimatedUpOnPlusY) {
  Vec3 up;
  const std::vector<CameraPose> poses = plan_camera_poses(handheld(8, 25, 1.0, 2));
  const std::vector<Mat3> r = in_first_camera(poses, &up);
  PoseSet set;
  for (std::size_t v = 0; v < r.size(); ++v) set.views.push_back({"v" + std::to_string(v), r[v], 0.1, std::nullopt});
  const WorldUp w = level_pose_set(set);
  EXPECT_EQ(set.gauge, "estimated-up");
  // The true world's up in the levelled frame: through any view, new_from_cam * cam_from_true_world * Y.
  for (std::size_t v = 0; v < r.size(); ++v) {
    const Vec3 true_up = set.views[v].world_from_cam * poses[v].world_from_cam.transpose() * Vec3(0, 1, 0);
    EXPECT_LT(angle_between(true_up, Vec3(0, 1, 0)) / kDeg, 1.0);
  }
  EXPECT_LT(angle_between(w.up, up) / kDeg, 1.0);
}

// Views left out of the estimate (in_estimate) do not move it, and are levelled with the rest: two
// of 8 handheld views (jittered 0.3 degrees) turned 12 degrees about their forward axis (a wrong chrome ball turns a view like this) give
// a tilted up when they join, and the true one when they are left out.
TEST(WorldUp, ViewsLeftOutOfTheEstimateAreLevelledButDoNotTiltIt) {
  Vec3 up;
  const std::vector<CameraPose> poses = plan_camera_poses(handheld(8, 25, 0.3, 5));
  std::vector<Mat3> r = in_first_camera(poses, &up);
  for (std::size_t v : {std::size_t(2), std::size_t(5)})
    r[v] = r[v] * Mat3(Eigen::AngleAxisd(12 * kDeg, Vec3(0, 0, 1)));
  auto make_set = [&] {
    PoseSet set;
    for (std::size_t v = 0; v < r.size(); ++v) set.views.push_back({"v" + std::to_string(v), r[v], 0.1, std::nullopt});
    return set;
  };
  PoseSet all = make_set(), some = make_set();
  WorldUpOptions o;
  o.min_roll_sigma_deg = 5;  // a loose roll scatter: the turned views keep their weight when they join
  const WorldUp with = level_pose_set(all, o);
  const WorldUp without = level_pose_set(some, o, {}, {1, 1, 0, 1, 1, 0, 1, 1});
  EXPECT_GT(angle_between(with.up, up) / kDeg, 1.0);
  EXPECT_LT(angle_between(without.up, up) / kDeg, 0.3);
  // Rolls per view, the two left out included: a turn of 12 degrees about a forward axis at elevation
  // e lifts the x axis out of level by asin(sin 12 cos e).
  ASSERT_EQ(without.roll_deg.size(), 8u);
  for (std::size_t v = 0; v < 8; ++v) {
    const double f_up = poses[v].world_from_cam.col(2).dot(Vec3(0, 1, 0));
    const double turned = std::asin(std::sin(12 * kDeg) * std::sqrt(1 - f_up * f_up)) / kDeg;
    if (v == 2 || v == 5)
      EXPECT_NEAR(std::abs(without.roll_deg[v]), turned, 0.3) << v;
    else
      EXPECT_LT(std::abs(without.roll_deg[v]), 1.0) << v;
  }
  // Every view, the two left out included, is turned by the same levelling.
  for (std::size_t v = 0; v < r.size(); ++v) {
    const Mat3 new_from_old = some.views[v].world_from_cam * r[v].transpose();
    EXPECT_LT((new_from_old - some.views[0].world_from_cam * r[0].transpose()).norm(), 1e-12);
  }
  PoseSet bad = make_set();
  EXPECT_THROW(level_pose_set(bad, o, {}, {1, 1}), std::invalid_argument);
  EXPECT_THROW(level_pose_set(bad, o, {}, std::vector<char>(8, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
