// Small synthetic views shared by the calib tests: one ball rig (capture/'s renderer, analytic sky)
// seen through a chosen lens, with the truth every calib stage is measured against.
#pragma once

#include "capture/camera_poses.h"
#include "capture/rig_renderer.h"
#include "capture/synth_capture.h"
#include "capture/synth_scene.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace rsibr::testing {

// The CC0 lobby environment (scripts/fetch-assets.sh); tests skip when it is missing.
inline const std::filesystem::path kLobby = std::filesystem::path(RSIBR_CACHE_DIR) / "assets/hdri/lobby.exr";

inline SynthScene rig_scene(const LensModel& lens, double distance_m, bool stand = true, double yaw_deg = 0) {
  const std::string text = R"(
rsibr_synth: 1
seed: 3
environment: {pattern: sun_and_sky, size: 256, sun_direction: [0.3, 0.8, 0.5], sun_radius_deg: 3,
              sun_rgb: [500, 450, 400], zenith_rgb: [0.2, 0.4, 1.0], horizon_rgb: [1.0, 0.9, 0.8]}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.07, 1.3, 0], albedo: [0.18, 0.18, 0.18]}
camera: {width: 64, height: 48, lens: {model: LENSMODEL_PINHOLE, focal_px: 100}}
views:
  - {plan: ring, count: 3, elevation_deg: 12, distance_m: 1}
)";
  SynthScene s = parse_synth_scene(text, "calib.yaml", ".");
  s.camera.lens = lens;
  s.stand = stand;
  s.photographer = stand;
  s.views.front().distance_m = distance_m;
  s.views.front().yaw_deg = yaw_deg;
  return s;
}

struct RenderedView {
  SynthScene scene;
  EnvMap env;
  CameraPose pose;
  cv::Mat radiance;  // CV_32FC3, noise added when asked
};

// View `view` of the rig; `noise` > 0 adds Gaussian noise of std dev noise * (value + 0.02)
// (shot-like relative noise with a read floor), seeded.
inline RenderedView render_view(const SynthScene& scene, int view = 0, double noise = 0.0, std::uint64_t seed = 5,
                                int supersampling = 3) {
  RenderedView r{scene, synth_environment(scene), plan_camera_poses(scene).at(view), {}};
  const RigRenderer renderer(scene, r.env);
  RigRenderOptions opt;
  opt.supersampling = supersampling;
  r.radiance = renderer.render(r.pose, scene.camera.lens, RayTable(scene.camera.lens), opt);
  if (noise > 0) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0, 1);
    for (auto it = r.radiance.begin<cv::Vec3f>(); it != r.radiance.end<cv::Vec3f>(); ++it)
      for (int c = 0; c < 3; ++c) (*it)[c] = std::max(0.0, (*it)[c] + noise * ((*it)[c] + 0.02) * g(rng));
  }
  return r;
}

// The true pixel of a ball's centre and its camera-frame centre.
inline Vec3 ball_centre_cam(const RenderedView& v, int ball) {
  return v.pose.world_from_cam.transpose() * (v.scene.balls.at(ball).centre - v.pose.eye);
}
inline Vec2 ball_centre_px(const RenderedView& v, int ball) {
  return v.scene.camera.lens.project(ball_centre_cam(v, ball));
}

// The middle element (the upper one of an even count); `x` non-empty.
inline double median(std::vector<double> x) {
  std::nth_element(x.begin(), x.begin() + long(x.size() / 2), x.end());
  return x[x.size() / 2];
}

}  // namespace rsibr::testing
