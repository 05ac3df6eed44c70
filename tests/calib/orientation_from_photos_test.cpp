// The issue's orientation target end to end, from photographs: a ring of 8 views 45 degrees apart
// around a 200-px chrome ball on its stand (lobby, with the photographer's proxy), each view 5
// bracketed 8-bit PNGs through the sensor model (shot and read noise, a measured-looking response,
// vignetting, white balance; capture/), the response recovered and the brackets merged (hdr/), the
// ball found and the views oriented from the merged images (calib/orientation/view_orientation.h), given only
// the true lens and the first view's up. Checked against the renderer's poses and balls.
#include "calib/orientation/view_orientation.h"

#include "calib_cases.h"
#include "capture/camera_poses.h"
#include "formats/photo_set.h"
#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "hdr/photo_set_merge.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::kLobby;
using testing::median;

SynthScene photo_ring_scene() {
  const std::string text = R"(
rsibr_synth: 1
seed: 4
environment: {file: )" + kLobby.string() +
                           R"(, sanitize: true}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [0, 1.3, 0]}
stand: true
photographer: true
camera:
  width: 500
  height: 460
  lens: {model: LENSMODEL_PINHOLE, focal_px: 2000}
  response: measured
  format: png
  supersampling: 2
  vignetting: 0.25
  white_balance: [1.1, 1.0, 0.85]
  full_well: 30000
  read_noise: 4
exposure: {middle_s: 0.004, count: 5, step_ev: 2, iso: 100, aperture: 8}
views:
  - {plan: ring, count: 8, elevation_deg: 8, distance_m: 0.5, roll_deg: 5}
)";
  return parse_synth_scene(text, "photo-ring.yaml", ".");
}

// Measured when set (release, 18 s): 612 tracks, median error 0.017 degrees (max 0.031), mean
// (error/sigma)^2 0.70, ball centres within 0.021 px median (max 0.059); with the scene's seed 7:
// 0.025 (max 0.041), 1.02, 0.022 px. Guarded at the issue's 0.05 degrees and 0.1 px.
TEST(OrientationFromPhotos, AnEightViewBracketedRingIsOrientedWithinTheIssuesFiveHundredthsOfADegree) {
  if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const fs::path root = fs::temp_directory_path() / ("rsibr-photo-ring-" + std::to_string(::getpid()));
  fs::remove_all(root);
  const SynthScene scene = photo_ring_scene();
  write_synth_capture(scene, root);
  const PhotoSet set = load_photo_set(root / "photos");
  ASSERT_EQ(set.views.size(), 8u);
  std::vector<const PhotoView*> all;
  for (const PhotoView& v : set.views) all.push_back(&v);
  const PhotoSetResponse response = recover_photo_set_response(all, RecoveryOptions{}, Alignment::off);
  std::vector<ViewImage> images;
  std::vector<std::string> names;
  for (const PhotoView& v : set.views) {
    const ViewMerge m = merge_photo_view(v, response.recovery.curve, std::nullopt, Alignment::off);
    ViewImage vi;
    vi.radiance = m.image.radiance;
    vi.flags = m.image.flags;
    vi.merged = true;
    images.push_back(vi);
    names.push_back(v.name);
  }
  fs::remove_all(root);

  const std::vector<CameraPose> truth = plan_camera_poses(scene);
  ASSERT_EQ(truth.size(), 8u);
  ViewOrientationOptions o;
  o.up = truth[0].world_from_cam.transpose() * Vec3(0, 1, 0);
  ViewOrientationReport rep;
  const PoseSet p = orient_views(names, images, scene.camera.lens, o, &rep);
  const Mat3 g = p.views[0].world_from_cam * truth[0].world_from_cam.transpose();
  std::vector<double> errors, centres;
  double chi2 = 0;
  for (std::size_t v = 0; v < truth.size(); ++v) {
    const Vec3 c = truth[v].world_from_cam.transpose() * (scene.balls.front().centre - truth[v].eye);
    centres.push_back((rep.balls[v].centre_px - scene.camera.lens.project(c)).norm());
    if (v == 0) continue;
    errors.push_back(Eigen::AngleAxisd(p.views[v].world_from_cam.transpose() * g * truth[v].world_from_cam).angle() *
                     180 / kPi);
    ASSERT_GT(p.views[v].sigma_deg, 0);
    chi2 += std::pow(errors.back() / p.views[v].sigma_deg, 2) / double(truth.size() - 1);
  }
  std::printf(
      "  %d tracks (%d re-located); orientation error median %.4f, max %.4f deg; mean (error/sigma)^2 %.2f; "
      "centre error median %.3f, max %.3f px\n",
      rep.tracks, rep.track_refinement.tracks_refined, median(errors), *std::max_element(errors.begin(), errors.end()),
      chi2, median(centres), *std::max_element(centres.begin(), centres.end()));
  EXPECT_LE(median(errors), 0.05);
  EXPECT_LT(*std::max_element(errors.begin(), errors.end()), 0.1);
  // Honest sigmas: the mean of 7 (error/sigma)^2, each ~ chi2_3 / 3 when honest, lies in [0.4, 1.9]
  // with 99% probability; guarded at [0.2, 3].
  EXPECT_GT(chi2, 0.2);
  EXPECT_LT(chi2, 3.0);
  EXPECT_LE(median(centres), 0.1);
}

}  // namespace
}  // namespace rsibr
