// rsibr process: a photo set to light probe, captured and computed maps, their comparison, a
// turntable render and an HTML report, as a graph of resumable steps (pipeline/step_record.h):
//
//   calibrate  chessboards -> DIR/camera.cameramodel (mrcal, model by cross-validation), or --lens,
//              or the photo set's model, or a pinhole from the photos' EXIF (calib/lens/photo_optics.h)
//   hdr        brackets -> DIR/hdr/<view>.exr, DIR/hdr/response.json (response recovered once),
//              DIR/hdr/vignetting.json (estimated from the chessboards, divided out of every view)
//   balls      every listed ball of every view found once, through the calibrated lens
//              (calib/balls/shoot_balls.h: candidates, the balls matched by appearance and size, a
//              missed chrome ball rescued, --ball given ones) -> DIR/balls.json (calib/balls/balls_file.h),
//              read by lens, orient and extract; each view's candidates numbered in DIR/balls/<view>.png
//   lens       the calibrated lens, its focal length refined from the balls' outlines when it came
//              from the photos' metadata (pipeline/lens_step.h) -> DIR/lens.cameramodel, the lens
//              of every later step (which refits the balls' cones to their outline pixels through it)
//   orient     -> DIR/poses.yaml (world_from_cam per view: solved from the chrome ball's features,
//              calib/orientation/view_orientation.h, world +Y up estimated from the views or given; or --poses,
//              whose chrome balls are refined here when the file has none)
//   extract    every ball of every view, identified and checked across views from the balls step's
//              candidates
//              (calib/balls/ball_identification.h) -> DIR/maps/captured-<ball>.exr, one part per view in
//              the world frame (chrome: reflection indexing, mirror warp, the other balls, the stands
//              and the photographer masked, calib/extraction/occluders.h; grey/glossy: orthographic), and each
//              chrome view's mask as DIR/masks/<view>.png; a ball not found in a view is left out;
//              with occluder_light (the default), the grey maps get back the light the photographer
//              takes from them (calib/extraction/occluded_light.h, from a probe of the chrome maps with the
//              clipped light recovered, lights/recovered_probe.h, and the view's own chrome map)
//   probe      chrome maps -> DIR/probe-measured.exr (lat-long, confidence-weighted blend)
//   sources    the light clipped in every chrome view, recovered from the grey (and glossy) balls
//              (pipeline/light_sources_step.h) -> DIR/probe.exr, the probe the later steps use
//   bake       probe -> DIR/maps/computed-<ball>.exr for every grey ball, Lambert of albedo
//              grey_albedo, at the captured views' directions and frames
//   compare    captured vs computed per grey ball -> DIR/compare/<ball>.json + side-by-side PNGs
//   render     probe -> DIR/render/maps.exr (icosa views of render_brdf) -> a turntable of the
//              mesh (or a built-in torus), DIR/render/frame_NN.png
//   report     -> DIR/report.html (pipeline/html_report.h)
//
// Each step reads its inputs from DIR (so a later run can start anywhere), writes its outputs
// atomically and then its record. Frames: world +Y up (the gauge of the poses).
#pragma once

#include "calib/probe/probe.h"
#include "core/vec.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct ProcessOptions {
  std::string photoset;        // photoset.yaml or its folder
  std::filesystem::path out;   // DIR (created; its parent must exist)
  std::string lens;            // given .cameramodel (skips the chessboards)
  bool self_calibrate = true;  // lens step: refine a metadata lens's focal length from the balls' outlines
  std::string poses;           // given poses (pipeline/pose_input.h); empty: the orientation solve
  std::string points;          // points picked by hand for the solve (calib/orientation/point_pairs.h); empty: none
  std::optional<Vec3> up;      // world up in the first camera's frame (e.g. 0,-1,0 for a levelled camera)
  bool estimate_up =
      true;  // without `up`: estimated from the views (calib/orientation/world_up.h); false: first-view gauge
  std::vector<std::string>
      ball_overrides;  // "VIEW:BALL=X,Y,R": that ball of that view located there (pipeline/ball_override.h)
  std::string
      input_colour_space;  // OCIO space of the linearised camera RGB; empty: the photo set's camera.colour_space, else the working space
  std::string vignetting =
      "auto";  // "auto" (from the chessboards when there are 3 or more), "none", or a JSON file (hdr/vignetting.h)
  // Stages swapped for given data (the truth of a synthetic capture: the error budget):
  std::string radiance_dir;        // hdr: linear EXRs <view>_radiance.exr or <view>.exr instead of the merge
  std::string probe_file;          // probe: this environment (resampled) instead of the chrome maps' blend
  std::string mesh;                // render: .glb/.gltf/.obj; empty: a built-in torus
  std::vector<std::string> force;  // steps to re-run ("all" for every step)
  int map_size = 0;                // extracted and computed sphere maps (texels a side); 0: pipeline/default_sizes.h
  int probe_width = 0;             // lat-long probe width; 0: pipeline/default_sizes.h
  // The chrome ball's Fresnel spec (YAML text), divided out of the probe; "" or "none": none (F L).
  std::string chrome_fresnel = kDefaultChromeFresnel;
  bool recover_sources = true;  // sources step: false writes the measured probe (lower bounds where clipped)
  bool fill_unseen = true;      // sources step: directions no view saw filled (calib/probe/probe_fill.h); false: 0
  std::string glossy_brdf;      // the glossy balls' BRDF spec (YAML text); empty: they are not used
  double grey_albedo = 0.18;    // the grey ball's Lambert albedo (compare fits a gain anyway)
  // extract: the light the photographer takes from each grey ball restored (calib/extraction/occluded_light.h),
  // so its maps are those of the ball under the environment alone (docs/tradeoffs.md, "Robust
  // geometry": the shoots' worst grey view within 0.1 stop of the truth with it, 0.2 without).
  bool occluder_light = true;
  std::string bake_method = "mis";
  int bake_samples = 128;
  // > 0: the bake step plans its integrator and samples instead (plan/bake_plan.h, plan_integrator):
  // the cheapest whose own error, against the full reference quadrature of the probe, is within
  // this relative RMS. The computed maps are baked at the captured frames, so nothing is interpolated.
  double bake_max_error = 0;
  std::uint64_t seed = 0;
  std::string render_brdf = "{type: ggx, roughness: 0.25, fresnel: {type: schlick, f0: [0.95, 0.64, 0.54]}}";
  int render_views_res = 64;  // map size of the render's computed map set (icosa views)
  int turntable = 8;          // frames
  int render_width = 320, render_height = 240;
  bool progress = false;                        // progress bars on stderr
  std::function<void(const std::string&)> log;  // one line per step (empty: silent)
};

struct StepOutcome {
  std::string step;
  bool ran = false;
  std::string reason;           // why it ran ("" when skipped: up to date)
  double seconds = 0;           // this run's time (0 when skipped)
  double recorded_seconds = 0;  // the time of the run that made the outputs
};

struct ProcessResult {
  std::vector<StepOutcome> steps;
  std::filesystem::path report;
  nlohmann::json summary;  // every step's summary by name
};

// The step names in order.
const std::vector<std::string>& process_steps();

// Throws std::invalid_argument("<file>: <problem>") for bad input (checked before any work where
// possible), std::runtime_error for failures inside a step (prefixed by the step's name). Outputs
// of steps that completed stay (with their records) so a re-run resumes after them.
ProcessResult run_process(const ProcessOptions& options);

}  // namespace rsibr
