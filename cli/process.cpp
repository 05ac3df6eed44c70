// rsibr process: the whole job, a photo set to probe, captured and computed maps, their comparison,
// a turntable and an HTML report (pipeline/process_pipeline.h), resumable step by step.
#include "cli/bake_planning.h"
#include "cli/option_checks.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "core/camera.h"
#include "formats/output_plan.h"
#include "formats/photo_set.h"
#include "core/progress.h"
#include "pipeline/process_pipeline.h"

#include <cstdio>
#include <iostream>
#include <sstream>

namespace rsibr::cli {
namespace {

struct ProcessArgs {
  ProcessOptions o;
  std::string size = "320x240", json, up = "auto", max_error;
  bool quiet = false, no_sources = false, no_self_calibration = false;
};

int run_process_verb(ProcessArgs a) {
  if (!a.max_error.empty()) a.o.bake_max_error = parse_error_budget(a.max_error);
  int w = 0, h = 0;
  char x = 0;
  std::istringstream in(a.size);
  if (!(in >> w >> x >> h) || x != 'x' || !(in >> std::ws).eof() || w < 16 || h < 16 || w > 8192 || h > 8192)
    throw std::invalid_argument("--size '" + a.size + "': expected WxH, 16..8192 each");
  if (a.up == "auto" || a.up == "none") {
    a.o.up.reset();
    a.o.estimate_up = a.up == "auto";
  } else {
    a.o.up = parse_vec3(a.up, "--up");
  }
  a.o.recover_sources = !a.no_sources;
  a.o.self_calibrate = !a.no_self_calibration;
  a.o.render_width = w;
  a.o.render_height = h;
  std::vector<std::filesystem::path> inputs = load_photo_set(a.o.photoset).files();
  for (const std::string& f : {a.o.lens, a.o.poses, a.o.probe_file, a.o.mesh})
    if (!f.empty()) inputs.push_back(f);
  OutputPlan outputs(inputs);
  outputs.folder(a.o.out.string());
  const std::string json = outputs.file(a.json);
  a.o.progress = !a.quiet && Progress::stderr_is_terminal();
  if (!a.quiet) a.o.log = [](const std::string& line) { std::cerr << "rsibr process: " << line << "\n"; };
  const ProcessResult r = run_process(a.o);
  nlohmann::json steps = nlohmann::json::array();
  for (const StepOutcome& s : r.steps)
    steps.push_back({{"step", s.step},
                     {"ran", s.ran},
                     {"reason", s.reason},
                     {"seconds", s.seconds},
                     {"recorded_seconds", s.recorded_seconds}});
  nlohmann::json j;
  j["photoset"] = a.o.photoset;
  j["out"] = a.o.out.string();
  j["report"] = r.report.string();
  j["steps"] = steps;
  j["results"] = r.summary;
  write_summary(json, j);
  outputs.commit();
  if (a.json != "-") std::cout << r.report.string() << "\n";
  return 0;
}

}  // namespace

Runner add_process(CLI::App& app) {
  auto a = std::make_shared<ProcessArgs>();
  CLI::App* c =
      app.add_subcommand("process", "The whole job: photo set -> probe, captured vs computed maps, render, report");
  c->footer(
      "Steps (each skipped when its inputs and outputs hold what its record says and its settings are unchanged; records in "
      "DIR/steps/<step>.json): calibrate (chessboards, --lens, or the photos' EXIF and the lensfun database) -> hdr "
      "(response, vignetting, merge per view) -> balls (every listed ball of every view found once, DIR/balls.json, "
      "candidates drawn in DIR/balls/<view>.png) -> lens (a lens from the EXIF: its focal length refined from the balls' "
      "outlines; --no-self-calibration: not) -> orient "
      "(solved from the chrome ball's features, world up estimated, or --poses) -> extract (every listed ball of every view, "
      "identified and checked across views; a ball not found in a view is left out and reported; chrome by reflection "
      "indexing with the other balls, stands and photographer masked, grey orthographic) -> probe "
      "(chrome maps blended) -> sources (light clipped in every chrome view recovered from the grey and glossy balls, "
      "written into the probe; --no-sources: not) -> bake (grey balls from the probe, Lambert) -> compare (captured vs computed, gains "
      "fitted) -> render (turntable of --mesh or a torus lit by the probe) -> report (DIR/report.html, "
      "self-contained). Prints the report's path.\n"
      "Example: rsibr process shoot/photoset.yaml --out shoot/out --poses shoot/poses.yaml");
  c->add_option("photoset", a->o.photoset, "photoset.yaml or the folder holding it")->required();
  c->add_option("--out", a->o.out, "Output folder DIR (created; its parent must exist)")->required();
  c->add_option("--lens", a->o.lens, "The camera's .cameramodel (instead of calibrating from chessboards)");
  c->add_option("--poses", a->o.poses, "Camera orientations: poses.yaml (rsibr orient) or a synth truth.yaml");
  c->add_option("--up", a->up,
                "World up: 'auto' (estimated from the views: cameras are held level in roll), "
                "X,Y,Z in the first camera's frame (0,-1,0 for a levelled camera), or 'none' (world = "
                "first camera)")
      ->capture_default_str();
  c->add_option("--points", a->o.points,
                "YAML of points picked by hand in two or more views' chrome balls (see the guide): they tie the "
                "views together where the features cannot");
  c->add_option("--ball", a->o.ball_overrides,
                "VIEW:BALL=X,Y,R: that ball of that view is at pixel (X, Y) with radius R "
                "(roughly), instead of the detection (repeatable)");
  c->add_option("--input-colorspace", a->o.input_colour_space,
                "OpenColorIO colour space of the linearised camera RGB (default: the photo set's camera.colour_space, "
                "else the working space; $OCIO honoured)");
  c->add_option("--vignetting", a->o.vignetting,
                "'auto' (estimated from the chessboards), 'none', or a JSON model "
                "(DIR/hdr/vignetting.json of another run)")
      ->capture_default_str();
  c->add_option("--radiance", a->o.radiance_dir,
                "Use these linear EXRs (<view>_radiance.exr or <view>.exr) instead of the merge");
  c->add_option("--probe", a->o.probe_file, "Use this environment as the probe instead of the chrome maps' blend");
  c->add_option("--mesh", a->o.mesh, "Mesh for the turntable (.glb, .gltf, .obj; default: a torus)");
  c->add_option("--force", a->o.force, "Re-run this step even if up to date (repeatable; 'all')");
  c->add_option("--map-size", a->o.map_size,
                "Sphere maps' size in texels (default: from each ball's pixel radius, pipeline/default_sizes.h)")
      ->check(CLI::Range(8, 2048));
  c->add_option("--probe-width", a->o.probe_width,
                "Lat-long probe width (default: as sharp as the sharpest chrome map, pipeline/default_sizes.h)")
      ->check(CLI::Range(8, 16384));
  c->add_option("--chrome-fresnel", a->o.chrome_fresnel,
                "The chrome ball's Fresnel spec, divided out of the probe ('none': the probe holds F L)")
      ->capture_default_str();
  c->add_flag(
      "--no-self-calibration", a->no_self_calibration,
      "Keep the focal length of a lens from the photos' EXIF as it is (no refinement from the balls' outlines)");
  c->add_flag(
      "--no-sources", a->no_sources,
      "Do not recover light clipped in every chrome view from the grey and glossy balls (probe.exr is the measured probe)");
  c->add_flag("!--no-fill", a->o.fill_unseen,
              "Leave the directions no view saw at 0 in probe.exr instead of filling them from their surroundings "
              "(confidence 0, flags 0)");
  c->add_option("--glossy-brdf", a->o.glossy_brdf,
                "The glossy balls' BRDF spec (YAML text): they then constrain the recovered sources");
  c->add_option("--grey-albedo", a->o.grey_albedo, "The grey ball's albedo")->check(CLI::Range(0.001, 1.0));
  c->add_flag("!--no-occluder-light", a->o.occluder_light,
              "Leave the grey maps as photographed: do not restore the light the photographer takes from "
              "them (read from each view's chrome ball; docs/tradeoffs.md, \"Robust geometry\")");
  c->add_option("--bake-method", a->o.bake_method, "Integrator of the computed maps: mis, fis, sh, reference");
  c->add_option("--bake-samples", a->o.bake_samples, "Samples per texel (mis, fis)")->check(CLI::Range(1, 1 << 20));
  c->add_option("--max-error", a->max_error,
                "Plan the computed maps' integrator and samples instead: the cheapest whose error against the "
                "probe's exact integral is within this relative RMS (e.g. 1%); the plan is in the bake step's record")
      ->check(error_budget_check())
      ->excludes("--bake-method")
      ->excludes("--bake-samples");
  c->add_option("--seed", a->o.seed, "Seed of every stochastic step")->check(seed_check());
  c->add_option("--render-brdf", a->o.render_brdf, "BRDF spec (YAML text) of the turntable's material");
  c->add_option("--turntable", a->o.turntable, "Turntable frames")->check(CLI::Range(1, 360));
  c->add_option("--size", a->size, "Turntable frame size WxH");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No progress or step lines");
  return [a] { return run_process_verb(*a); };
}

}  // namespace rsibr::cli
