// Small synthetic scenes shared by the capture tests (analytic sky, so they always run).
#pragma once

#include "capture/synth_scene.h"

#include <string>

namespace rsibr::testing {

// A sky with a sun, one chrome and one grey ball, a pinhole lens; `extra` is appended to the root.
inline std::string small_scene_text(const std::string& camera_extra = "", const std::string& extra = "") {
  return R"(
rsibr_synth: 1
seed: 7
environment: {pattern: sun_and_sky, size: 128, sun_direction: [0.3, 0.8, 0.5], sun_radius_deg: 3,
              sun_rgb: [500, 450, 400], zenith_rgb: [0.2, 0.4, 1.0], horizon_rgb: [1.0, 0.9, 0.8]}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.06, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.06, 1.3, 0], albedo: [0.18, 0.18, 0.18]}
camera: {width: 96, height: 72, lens: {model: LENSMODEL_PINHOLE, focal_px: 200}, supersampling: 2)" +
         camera_extra + R"(}
exposure: {middle_s: 0.01, count: 3, step_ev: 2}
views:
  - {plan: ring, count: 2, elevation_deg: 10, distance_m: 0.8}
truth_map_size: 16
)" + extra;
}

inline SynthScene small_scene(const std::string& camera_extra = "", const std::string& extra = "") {
  return parse_synth_scene(small_scene_text(camera_extra, extra), "small.yaml", ".");
}

}  // namespace rsibr::testing
