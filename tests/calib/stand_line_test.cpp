// The stand under a ball as a vertical line (calib/orientation/stand_line.h), on rendered views of a chrome ball
// on its pole in the CC0 lobby: the plane it gives contains the true up; without a stand, none.
#include "calib/orientation/stand_line.h"

#include "calib_cases.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::kLobby;

SynthScene stand_scene(bool stand) {
  const std::string text = R"(
rsibr_synth: 1
seed: 5
environment: {file: )" + kLobby.string() +
                           R"(, sanitize: true}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.07, 1.3, 0]}
camera: {width: 320, height: 240, lens: {model: LENSMODEL_OPENCV4, focal_px: 330, distortion: [-0.05, 0.01, 0, 0]}}
views:
  - {plan: handheld, count: 3, elevation_deg: 20, distance_m: 0.6, jitter_m: 0.01, jitter_deg: 2.0}
)";
  SynthScene s = parse_synth_scene(text, "stand.yaml", ".");
  s.stand = stand;
  s.photographer = false;
  return s;
}

TEST(StandLine, ThePolesPlaneContainsTheTrueUp) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const SynthScene scene = stand_scene(true);
  for (int v = 0; v < 3; ++v) {
    const testing::RenderedView r = testing::render_view(scene, v, 0.002, 5, 2);
    const Vec3 c = testing::ball_centre_cam(r, 0);
    const auto line = find_stand_line(r.radiance, scene.camera.lens, {c.normalized(), std::asin(0.05 / c.norm())});
    ASSERT_TRUE(line.has_value()) << "view " << v;
    const Vec3 up_cam = r.pose.world_from_cam.transpose() * Vec3(0, 1, 0);
    const double off_deg = std::asin(std::abs(line->plane_normal.dot(up_cam))) * 180 / kPi;
    std::printf(
        "  view %d: up %.3f degrees off the pole's plane (sigma %.3f), line at %.1f degrees, half width %.1f px\n", v,
        off_deg, line->sigma_deg, line->angle_deg, line->half_width_px);
    EXPECT_LT(off_deg, 0.5) << v;
    EXPECT_LT(off_deg, 4 * line->sigma_deg + 0.05) << v;
    EXPECT_LT(line->sigma_deg, 1.0);
  }
}

TEST(StandLine, WithoutAStandThereIsNoLine) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const SynthScene scene = stand_scene(false);
  const testing::RenderedView r = testing::render_view(scene, 0, 0.002, 5, 2);
  const Vec3 c = testing::ball_centre_cam(r, 0);
  EXPECT_FALSE(
      find_stand_line(r.radiance, scene.camera.lens, {c.normalized(), std::asin(0.05 / c.norm())}).has_value());
}

}  // namespace
}  // namespace rsibr
