#include "pipeline/process_pipeline.h"

#include "calib/balls/ball_candidates_picture.h"
#include "calib/balls/balls_file.h"
#include "calib/balls/shoot_balls.h"
#include "calib/lens/far_camera.h"
#include "calib/orientation/point_pairs.h"
#include "calib/orientation/pose_file.h"
#include "calib/view_image.h"
#include "core/lens_model.h"
#include "formats/atomic_folder.h"
#include "formats/file_error.h"
#include "formats/map_set.h"
#include "formats/photo_set.h"
#include "lights/recovered_probe.h"
#include "pipeline/ball_override.h"
#include "pipeline/bake_step.h"
#include "pipeline/calibrate_step.h"
#include "pipeline/compare_step.h"
#include "pipeline/extract_step.h"
#include "pipeline/hdr_step.h"
#include "pipeline/html_report.h"
#include "pipeline/lens_step.h"
#include "pipeline/light_sources_report.h"
#include "pipeline/light_sources_step.h"
#include "pipeline/orient_step.h"
#include "pipeline/pose_input.h"
#include "pipeline/probe_step.h"
#include "pipeline/process_checks.h"
#include "pipeline/render_step.h"
#include "pipeline/step_record.h"
#include "pipeline/vignetting_input.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

struct Context {
  const ProcessOptions& o;
  fs::path dir;
  PhotoSet set;
  ProcessResult& result;
};

// A fact an earlier step recorded in its summary (DIR/steps/STEP.json) that a later step needs:
// its absence is an error naming the step, never a default.
const nlohmann::json& recorded(const Context& c, const std::string& step, const std::string& key) {
  const nlohmann::json& all = c.result.summary;
  if (!all.contains(step) || !all.at(step).is_object() || !all.at(step).contains(key))
    throw std::runtime_error(step + ": its record has no '" + key + "' (rerun with --force " + step + ")");
  return all.at(step).at(key);
}

// Runs `body` unless the step is up to date; body fills outputs and summary.
void run_step(Context& c, const std::string& step, const nlohmann::json& settings, const std::vector<fs::path>& inputs,
              const std::function<void(StepRecord&)>& body) {
  const bool forced = std::find(c.o.force.begin(), c.o.force.end(), step) != c.o.force.end() ||
                      std::find(c.o.force.begin(), c.o.force.end(), "all") != c.o.force.end();
  const RecordRoots roots{c.dir, c.set.folder};
  std::string reason = forced ? "forced" : step_stale_reason(c.dir, step, settings, inputs, roots);
  StepOutcome outcome;
  outcome.step = step;
  if (reason.empty()) {
    const StepRecord old = read_step_record(c.dir, step, roots);
    outcome.recorded_seconds = old.seconds;
    c.result.summary[step] = old.summary;
    c.result.steps.push_back(outcome);
    if (c.o.log) c.o.log(step + ": up to date, skipped");
    return;
  }
  if (c.o.log) c.o.log(step + ": running (" + reason + ")");
  const auto t0 = std::chrono::steady_clock::now();
  StepRecord r;
  r.step = step;
  r.settings = settings;
  r.inputs = inputs;
  // A step that stops leaves what it found and why (steps/STEP.failed.json), never its record.
  auto failed = [&](const std::string& why) {
    try {
      write_failed_step_record(c.dir, r, why);
    } catch (const std::exception&) {
      // The step's own error is the one to report.
    }
  };
  try {
    body(r);
  } catch (const std::invalid_argument& e) {
    failed(e.what());
    throw;
  } catch (const FileError& e) {
    failed(e.what());
    throw e.in_step(step);
  } catch (const std::exception& e) {
    failed(e.what());
    throw std::runtime_error(step + ": " + e.what());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_step_record(c.dir, r, roots);
  remove_failed_step_record(c.dir, step);
  outcome.ran = true;
  outcome.reason = reason;
  outcome.seconds = outcome.recorded_seconds = r.seconds;
  c.result.summary[step] = r.summary;
  c.result.steps.push_back(outcome);
}

// A step's files and summary into its record.
void take(StepRecord& r, StepOutputs o) {
  r.outputs = std::move(o.files);
  r.summary = std::move(o.summary);
}

// A view's merged image; view names are safe file names (core/safe_name.h), checked again here.
fs::path merged_path(const Context& c, const std::string& view) { return file_in_folder(c.dir / "hdr", view + ".exr"); }

std::vector<fs::path> hdr_files(const Context& c) {
  std::vector<fs::path> files;
  for (const PhotoView& v : c.set.views) files.push_back(merged_path(c, v.name));
  return files;
}

std::vector<const BallSpec*> balls_of(const Context& c, BallKind kind) {
  std::vector<const BallSpec*> out;
  for (const BallSpec& b : c.set.balls)
    if (b.kind == kind) out.push_back(&b);
  return out;
}

fs::path captured_path(const Context& c, const BallSpec& b) {
  return file_in_folder(c.dir / "maps", "captured-" + b.name + ".exr");
}
fs::path computed_path(const Context& c, const BallSpec& b) {
  return file_in_folder(c.dir / "maps", "computed-" + b.name + ".exr");
}

// ---- calibrate: the lens model (pipeline/calibrate_step.h) -> DIR/camera.cameramodel.
void step_calibrate(Context& c) {
  const fs::path out = c.dir / "camera.cameramodel";
  std::vector<fs::path> inputs;
  nlohmann::json settings;
  if (!c.o.lens.empty()) {
    inputs.push_back(c.o.lens);
    settings = {{"source", "given"}};
  } else if (c.set.chessboards) {
    inputs = c.set.chessboards->files;
    settings = {{"source", "chessboards"}, {"models", kCalibrateModels}};
  } else if (c.set.camera_model) {
    inputs.push_back(*c.set.camera_model);
    settings = {{"source", "photo set"}};
  } else {
    // The photos' own metadata: the first view's first bracket (calib/lens/photo_optics.h).
    if (c.set.views.empty() || c.set.views[0].brackets.empty())
      throw std::invalid_argument(c.o.photoset + ": no views");
    inputs.push_back(c.set.views[0].brackets[0].file);
    settings = {{"source", "exif"}};
  }
  run_step(c, "calibrate", settings, inputs, [&](StepRecord& r) {
    CalibrateStep st;
    st.set = &c.set;
    st.photoset = c.o.photoset;
    st.source = settings["source"].get<std::string>();
    if (!inputs.empty() && st.source != "chessboards") st.file = inputs.front();
    st.out = out;
    st.progress = c.o.progress;
    r.summary = run_calibrate_step(st);
    r.outputs = {out};
  });
}

// ---- hdr: response once, then every view's merge (pipeline/hdr_step.h) -> DIR/hdr/; or the given
// radiance (--radiance-dir) as merged views.
void step_hdr(Context& c) {
  if (!c.o.radiance_dir.empty()) {
    const std::vector<fs::path> inputs = given_radiance_files(c.set, c.o.radiance_dir);
    run_step(c, "hdr", {{"response", "given radiance"}, {"radiance", c.o.radiance_dir}}, inputs,
             [&](StepRecord& r) { take(r, run_given_radiance_step(c.set, inputs, c.o.radiance_dir, c.dir / "hdr")); });
    return;
  }
  std::vector<fs::path> inputs;
  for (const PhotoView& v : c.set.views)
    for (const BracketPhoto& b : v.brackets) inputs.push_back(b.file);
  // Vignetting (pipeline/vignetting_input.h): its inputs and the lens's principal point.
  for (const fs::path& f : vignetting_inputs(c.set, c.o.vignetting)) inputs.push_back(f);
  if (c.o.vignetting != "none") inputs.push_back(c.dir / "camera.cameramodel");
  HdrStep s;
  s.set = &c.set;
  s.vignetting = c.o.vignetting;
  s.lens = c.dir / "camera.cameramodel";
  s.input_colour_space = c.o.input_colour_space;
  s.out = c.dir / "hdr";
  s.progress = c.o.progress;
  const std::string input_space = !c.o.input_colour_space.empty() ? c.o.input_colour_space : c.set.camera_colour_space;
  run_step(c, "hdr", {{"response", "auto"}, {"vignetting", c.o.vignetting}, {"input_colour_space", input_space}},
           inputs, [&](StepRecord& r) { take(r, run_hdr_step(s)); });
}

// ---- balls: every listed ball of every view found once (calib/balls/shoot_balls.h), through the
// calibrated lens -> DIR/balls.json (calib/balls/balls_file.h), read by lens, orient and extract,
// and each view's candidates circled and numbered in DIR/balls/<view>.png (what --ball is picked from).
void step_balls(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "camera.cameramodel");
  ShootBallsInput in;
  in.listed = listed_balls(c.set);
  const std::vector<BallOverride> overrides = parse_ball_overrides(c.o.ball_overrides, c.set);
  nlohmann::json given = nlohmann::json::array(), balls = nlohmann::json::array();
  const nlohmann::json& hdr = c.result.summary["hdr"];
  for (const PhotoView& v : c.set.views) {
    in.views.push_back(v.name);
    in.suspect_bracket.push_back(suspect_bracket(v.name, hdr));
    in.given.emplace_back();
    for (const ListedBall& b : in.listed) {
      in.given.back().push_back(find_override(overrides, v.name, b.name));
      if (const auto& g = in.given.back().back())
        given.push_back({v.name, b.name, g->centre_px.x(), g->centre_px.y(), g->radius_px});
    }
  }
  for (const ListedBall& b : in.listed) balls.push_back({b.name, to_string(b.kind), b.diameter_m.value_or(0.0)});
  run_step(c, "balls", {{"balls", balls}, {"given", given}}, inputs, [&](StepRecord& r) {
    in.lens = LensModel::read(c.dir / "camera.cameramodel");
    in.read_view = [&](std::size_t v) { return read_view_image(merged_path(c, c.set.views[v].name).string()); };
    // Each view's candidates drawn as it is searched (views in parallel); listed in view order.
    fs::create_directories(c.dir / "balls");
    in.seen = [&](std::size_t v, const cv::Mat& radiance, const ViewCandidates& vc) {
      write_ball_candidates_picture(file_in_folder(c.dir / "balls", c.set.views[v].name + ".png"), radiance, vc);
    };
    const ShootBalls found = find_shoot_balls(in);
    nlohmann::json pictures = nlohmann::json::array();
    for (const PhotoView& v : c.set.views) {
      r.outputs.push_back(file_in_folder(c.dir / "balls", v.name + ".png"));
      pictures.push_back(fs::relative(r.outputs.back(), c.dir).string());
    }
    write_balls_file(c.dir / "balls.json", found);
    r.outputs.push_back(c.dir / "balls.json");
    r.summary = balls_summary_json(found);
    r.summary["candidates_pictures"] = pictures;
  });
}

// The balls step's findings, for the photo set's balls.
ShootBalls read_found_balls(const Context& c) {
  ShootBalls found = read_balls_file(c.dir / "balls.json");
  check_listed_balls(found, listed_balls(c.set), (c.dir / "balls.json").string());
  return found;
}

// ---- lens: the calibrated lens, its focal length refined from the balls' outlines when it came
// from the photos' metadata (pipeline/lens_step.h) -> DIR/lens.cameramodel, the lens of every
// later step.
void step_lens(Context& c) {
  const std::vector<fs::path> inputs = {c.dir / "balls.json", c.dir / "camera.cameramodel"};
  LensStep s;
  s.calibrated = c.dir / "camera.cameramodel";
  s.source = recorded(c, "calibrate", "source").get<std::string>();
  // A focal length from the metadata has a prior sigma; a lens from boards or a file has none.
  if (s.source == "exif" || s.source == "lensfun")
    s.prior_sigma_relative = recorded(c, "calibrate", "focal_sigma_relative").get<double>();
  if (s.source == "outlines") s.metadata_note = recorded(c, "calibrate", "lensfun").get<std::string>();
  s.refine = c.o.self_calibrate;
  s.out = c.dir / "lens.cameramodel";
  s.pictures = c.dir / "balls";
  const nlohmann::json settings = {{"refine", s.refine},
                                   {"source", s.source},
                                   {"prior_sigma_relative", s.prior_sigma_relative},
                                   {"crops", "far camera"}};
  run_step(c, "lens", settings, inputs, [&](StepRecord& r) {
    s.balls = read_found_balls(c);
    r.summary = run_lens_step(s);
    r.outputs = {s.out};
  });
}

// A view's merged image as the later steps read it: on the lens's canvas when the lens step chose
// the far camera for crops of the ball (calib/lens/far_camera.h), else of the lens's size exactly.
ViewImage read_merged_view(const Context& c, const PhotoView& v, const LensModel& lens) {
  const std::string file = merged_path(c, v.name).string();
  ViewImage img = read_view_image(file);
  if (recorded(c, "lens", "far_camera").get<bool>()) return on_lens_canvas(std::move(img), lens, file);
  if (img.radiance.cols != lens.width() || img.radiance.rows != lens.height())
    throw std::invalid_argument(file + ": " + std::to_string(img.radiance.cols) + "x" +
                                std::to_string(img.radiance.rows) + " but the lens model is " +
                                std::to_string(lens.width()) + "x" + std::to_string(lens.height()));
  return img;
}

// ---- orient: world_from_cam per view (pipeline/orient_step.h) -> DIR/poses.yaml, and each pair's
// matches drawn in DIR/orient/A--B.png.
void step_orient(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "lens.cameramodel");
  OrientStep s;
  if (!c.o.points.empty()) {
    if (!c.o.poses.empty()) throw std::invalid_argument("--points: not with --poses (the poses are given)");
    inputs.push_back(c.o.points);
  }
  if (!c.o.poses.empty()) {
    inputs.push_back(c.o.poses);
    s.given = read_given_poses(c.o.poses);
    s.given_file = c.o.poses;
    for (const PhotoView& v : c.set.views)
      if (!s.given->find(v.name)) throw std::invalid_argument(c.o.poses + ": no pose for view '" + v.name + "'");
  }
  inputs.push_back(c.dir / "balls.json");
  const nlohmann::json settings = {{"source", c.o.poses.empty() ? "solve" : "given"},
                                   {"up", c.o.up ? nlohmann::json{c.o.up->x(), c.o.up->y(), c.o.up->z()}
                                                 : nlohmann::json(c.o.estimate_up ? "auto" : "none")}};
  run_step(c, "orient", settings, inputs, [&](StepRecord& r) {
    const LensModel lens = LensModel::read(c.dir / "lens.cameramodel");
    s.lens = &lens;
    for (const PhotoView& v : c.set.views) s.views.push_back(v.name);
    s.read_view = [&](const std::string& name) {
      for (const PhotoView& v : c.set.views)
        if (v.name == name) return read_merged_view(c, v, lens);
      throw std::logic_error("orient: no view " + name);
    };
    s.found = read_found_balls(c);
    if (!c.o.points.empty()) s.points = read_point_pairs(c.o.points);
    s.up = c.o.up;
    s.estimate_up = c.o.estimate_up;
    s.pictures = c.dir / "orient";
    const OrientedViews o = run_orient_step(s, &r.summary);
    const fs::path out = c.dir / "poses.yaml";
    write_pose_file(out.string(), o.poses);
    r.outputs = o.pictures;
    r.outputs.push_back(out);
    r.summary = o.summary;
  });
}

// ---- extract: every listed ball of every view, in the world frame (pipeline/extract_step.h) ->
// DIR/maps/captured-<ball>.exr and each map's mask in DIR/masks/.
void step_extract(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "lens.cameramodel");
  inputs.push_back(c.dir / "poses.yaml");
  inputs.push_back(c.dir / "balls.json");
  nlohmann::json settings = {{"map_size", c.o.map_size}};
  if (c.o.occluder_light)
    settings["occluder_light"] = {{"fresnel", c.o.chrome_fresnel},
                                  {"probe_width", c.o.probe_width},
                                  {"recover", c.o.recover_sources},
                                  {"albedo", c.o.grey_albedo},
                                  {"seed", c.o.seed}};
  run_step(c, "extract", settings, inputs, [&](StepRecord& r) {
    if (c.set.balls.empty()) throw std::invalid_argument(c.o.photoset + ": balls: the photo set lists no ball");
    const LensModel lens = LensModel::read(c.dir / "lens.cameramodel");
    ExtractStep s;
    s.lens = &lens;
    s.poses = read_pose_file((c.dir / "poses.yaml").string());
    s.found = read_found_balls(c);
    for (const PhotoView& v : c.set.views) s.views.push_back(v.name);
    s.read_view = [&](const std::string& name) {
      for (const PhotoView& v : c.set.views)
        if (v.name == name) return read_merged_view(c, v, lens);
      throw std::logic_error("extract: no view " + name);
    };
    s.map_size = c.o.map_size;
    s.probe_width = c.o.probe_width;
    s.occluder_light = c.o.occluder_light;
    s.chrome_fresnel = c.o.chrome_fresnel;
    s.recover_sources = c.o.recover_sources;
    s.grey_albedo = c.o.grey_albedo;
    s.seed = c.o.seed;
    s.progress = c.o.progress;
    ExtractedMaps e = run_extract_step(s);
    fs::create_directories(c.dir / "maps");
    for (std::size_t bi = 0; bi < c.set.balls.size(); ++bi) {
      const fs::path out = captured_path(c, c.set.balls[bi]);
      write_map_set(out.string(), e.sets[bi]);
      r.outputs.push_back(out);
    }
    if (!e.masks.empty()) {
      write_folder_atomically(c.dir / "masks", e.masks);
      for (const auto& [name, bytes] : e.masks) r.outputs.push_back(c.dir / "masks" / name);
    }
    r.summary = std::move(e.summary);
  });
}

// The probe's width: the user's, else the one the extract step chose (pipeline/default_sizes.h).
int probe_width(const Context& c) {
  if (c.o.probe_width > 0) return c.o.probe_width;
  return recorded(c, "extract", "probe_width").get<int>();
}

// ---- probe: the chrome maps blended (pipeline/probe_step.h) -> DIR/probe-measured.exr.
void step_probe(Context& c) {
  ProbeStep s;
  s.width = probe_width(c);
  s.chrome_fresnel = c.o.chrome_fresnel;
  s.given = c.o.probe_file;
  s.out = c.dir / "probe-measured.exr";
  const auto chrome = balls_of(c, BallKind::chrome);
  if (chrome.empty()) throw std::invalid_argument(c.o.photoset + ": balls: no chrome ball (the probe needs one)");
  for (const BallSpec* b : chrome) s.chrome_maps.push_back(captured_path(c, *b));
  // The stage swapped for a given environment (the truth, for the error budget).
  const nlohmann::json settings = s.given.empty() ? nlohmann::json{{"width", s.width}, {"fresnel", s.chrome_fresnel}}
                                                  : nlohmann::json{{"width", s.width}, {"given", s.given}};
  const std::vector<fs::path> inputs = s.given.empty() ? s.chrome_maps : std::vector<fs::path>{s.given};
  run_step(c, "probe", settings, inputs, [&](StepRecord& r) { take(r, run_probe_step(s)); });
}

// ---- sources: the clipped light recovered from the grey and glossy balls -> DIR/probe.exr.
void step_sources(Context& c) {
  LightSourcesStep s;
  std::vector<fs::path> inputs = {c.dir / "probe-measured.exr"};
  for (const BallSpec* b : balls_of(c, BallKind::chrome)) s.chrome.push_back(captured_path(c, *b));
  for (const BallSpec* b : balls_of(c, BallKind::grey)) s.grey.push_back({b->name, captured_path(c, *b)});
  for (const BallSpec* b : balls_of(c, BallKind::glossy)) s.glossy.push_back({b->name, captured_path(c, *b)});
  s.given_probe = !c.o.probe_file.empty();
  // The balls' maps and settings matter only when the probe step found light clipped in every view.
  const bool clipped = !s.given_probe && recorded(c, "probe", "clipped_fraction").get<double>() > 0;
  if (!s.given_probe) inputs.insert(inputs.end(), s.chrome.begin(), s.chrome.end());
  if (clipped) {
    for (const auto& g : s.grey) inputs.push_back(g.second);
    if (!c.o.glossy_brdf.empty())
      for (const auto& g : s.glossy) inputs.push_back(g.second);
  }
  s.glossy_brdf = c.o.glossy_brdf;
  s.measured = c.dir / "probe-measured.exr";
  s.out = c.dir / "probe.exr";
  s.probe_width = probe_width(c);
  s.chrome_fresnel = c.o.chrome_fresnel;
  s.grey_albedo = c.o.grey_albedo;
  s.recover = c.o.recover_sources;
  s.fill = c.o.fill_unseen;
  s.seed = c.o.seed;
  nlohmann::json settings = {{"recover", s.recover},        {"fill", s.fill},         {"width", s.probe_width},
                             {"fresnel", s.chrome_fresnel}, {"given", s.given_probe}, {"clipped", clipped}};
  if (clipped) settings.update({{"albedo", s.grey_albedo}, {"glossy_brdf", s.glossy_brdf}, {"seed", s.seed}});
  run_step(c, "sources", settings, inputs, [&](StepRecord& r) {
    r.summary = run_light_sources_step(s);
    r.outputs = {s.out};
    if (c.o.log) {
      const std::string line = light_sources_line(r.summary);
      if (!line.empty()) c.o.log("sources: " + line);
    }
  });
}

// ---- bake: computed maps of the grey balls from the probe, at the captured views
// (pipeline/bake_step.h) -> DIR/maps/computed-<ball>.exr.
void step_bake(Context& c) {
  BakeStep s;
  s.probe = c.dir / "probe.exr";
  std::vector<fs::path> inputs = {s.probe};
  for (const BallSpec* b : balls_of(c, BallKind::grey)) {
    s.balls.push_back({b->name, captured_path(c, *b), computed_path(c, *b)});
    inputs.push_back(s.balls.back().captured);
  }
  s.albedo = c.o.grey_albedo;
  s.method = c.o.bake_method;
  s.samples = c.o.bake_samples;
  s.max_error = c.o.bake_max_error;
  s.seed = c.o.seed;
  s.log = c.o.log;
  nlohmann::json settings = {
      {"albedo", c.o.grey_albedo}, {"method", c.o.bake_method}, {"samples", c.o.bake_samples}, {"seed", c.o.seed}};
  if (c.o.bake_max_error > 0)
    settings = {{"albedo", c.o.grey_albedo}, {"max_error", c.o.bake_max_error}, {"seed", c.o.seed}};
  run_step(c, "bake", settings, inputs, [&](StepRecord& r) { take(r, run_bake_step(s)); });
}

// ---- compare: captured against computed, per grey ball (pipeline/compare_step.h) -> DIR/compare/.
void step_compare(Context& c) {
  CompareStep s;
  s.out = c.dir / "compare";
  std::vector<fs::path> inputs;
  for (const BallSpec* b : balls_of(c, BallKind::grey)) {
    s.balls.push_back({b->name, captured_path(c, *b), computed_path(c, *b)});
    inputs.push_back(s.balls.back().captured), inputs.push_back(s.balls.back().computed);
  }
  run_step(c, "compare", nlohmann::json::object(), inputs, [&](StepRecord& r) { take(r, run_compare_step(s)); });
}

// ---- render: a turntable of a mesh lit by the probe, through the runtime (pipeline/render_step.h)
// -> DIR/render/.
void step_render(Context& c) {
  RenderStep s;
  s.probe = c.dir / "probe.exr";
  s.mesh = c.o.mesh;
  s.brdf = c.o.render_brdf;
  s.views_res = c.o.render_views_res;
  s.frames = c.o.turntable;
  s.width = c.o.render_width;
  s.height = c.o.render_height;
  s.seed = c.o.seed;
  s.progress = c.o.progress;
  s.out = c.dir / "render";
  std::vector<fs::path> inputs = {s.probe};
  if (!c.o.mesh.empty()) inputs.push_back(c.o.mesh);
  const nlohmann::json settings = {{"brdf", c.o.render_brdf}, {"res", c.o.render_views_res},
                                   {"frames", c.o.turntable}, {"size", {c.o.render_width, c.o.render_height}},
                                   {"seed", c.o.seed},        {"mesh", c.o.mesh.empty() ? "built-in torus" : c.o.mesh}};
  run_step(c, "render", settings, inputs, [&](StepRecord& r) { take(r, run_render_step(s)); });
}

}  // namespace

const std::vector<std::string>& process_steps() {
  static const std::vector<std::string> steps = {"calibrate", "hdr",     "balls", "lens",    "orient", "extract",
                                                 "probe",     "sources", "bake",  "compare", "render", "report"};
  return steps;
}

ProcessResult run_process(const ProcessOptions& o) {
  check_process_options(o);  // errors before any work
  ProcessResult result;
  Context c{o, fs::absolute(o.out).lexically_normal(), load_photo_set(o.photoset), result};
  check_process_inputs(o, c.set, c.dir);
  fs::create_directories(c.dir);

  try {
    step_calibrate(c);
    step_hdr(c);
    step_balls(c);
    step_lens(c);
    step_orient(c);
    step_extract(c);
    step_probe(c);
    step_sources(c);
    step_bake(c);
    step_compare(c);
    step_render(c);
  } catch (...) {
    // The report up to the step that stopped, with that step's error and pictures; best effort:
    // the step's own error is what the user is told.
    try {
      write_process_report(c.dir, c.dir / "report.html", c.set.folder.string());
    } catch (const std::exception&) {
    }
    throw;
  }

  // The report reads every record (timings included), so it runs whenever any step did.
  std::vector<fs::path> inputs;
  for (const std::string& s : process_steps())
    if (s != "report") inputs.push_back(step_record_path(c.dir, s));
  run_step(c, "report", nlohmann::json::object(), inputs, [&](StepRecord& r) {
    const fs::path out = c.dir / "report.html";
    write_process_report(c.dir, out, c.set.folder.string());
    r.outputs = {out};
    r.summary = {{"report", out.string()}};
  });
  result.report = c.dir / "report.html";
  return result;
}

}  // namespace rsibr
