#include "pipeline/process_pipeline.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "plan/bake_plan.h"
#include "calib/balls/ball_identification.h"
#include "calib/balls/ball_locator.h"
#include "calib/lens/far_camera.h"
#include "calib/lens/intrinsics.h"
#include "calib/lens/photo_optics.h"
#include "calib/extraction/lambert_consensus.h"
#include "calib/extraction/occluded_light.h"
#include "calib/extraction/occluders.h"
#include "calib/probe/probe.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "calib/view_image.h"
#include "calib/orientation/view_orientation.h"
#include "calib/orientation/pair_matches_picture.h"
#include "calib/orientation/pose_file.h"
#include "formats/atomic_file.h"
#include "formats/atomic_folder.h"
#include "core/camera.h"
#include "formats/file_error.h"
#include "core/colour.h"
#include "compare/compare_pictures.h"
#include "formats/exr_io.h"
#include "core/lens_model.h"
#include "compare/comparison_report.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "formats/photo_set.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/resample.h"
#include "core/view_set.h"
#include "formats/yaml_spec.h"
#include "hdr/bracket_set.h"
#include "hdr/merge.h"
#include "hdr/merged_colour.h"
#include "hdr/merged_exr.h"
#include "hdr/noise_model.h"
#include "hdr/photo_set_merge.h"
#include "hdr/response_recovery.h"
#include "lights/recovered_probe.h"
#include "pipeline/ball_override.h"
#include "pipeline/chessboard_problem.h"
#include "pipeline/default_sizes.h"
#include "pipeline/extract_step.h"
#include "pipeline/html_report.h"
#include "pipeline/lens_step.h"
#include "pipeline/light_sources_step.h"
#include "pipeline/mask_picture.h"
#include "pipeline/orientation_json.h"
#include "pipeline/pose_input.h"
#include "pipeline/step_record.h"
#include "pipeline/torus_mesh.h"
#include "pipeline/vignetting_input.h"
#include "runtime/renderer.h"
#include "formats/image_codecs.h"

#include <yaml-cpp/yaml.h>

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

constexpr double kPiD = 3.14159265358979323846;

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

// ---- calibrate: the lens model.
void step_calibrate(Context& c) {
  const fs::path out = c.dir / "camera.cameramodel";
  std::vector<fs::path> inputs;
  nlohmann::json settings;
  if (!c.o.lens.empty()) {
    inputs.push_back(c.o.lens);
    settings = {{"source", "given"}};
  } else if (c.set.chessboards) {
    inputs = c.set.chessboards->files;
    settings = {{"source", "chessboards"}, {"models", {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8"}}};
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
    nlohmann::json s;
    if (settings["source"] == "exif") {
      const BracketSet b = load_brackets(c.set.views[0], true);
      // lensfun's profile of the lens the EXIF names (distortion included), else a pinhole.
      const std::optional<MetadataLens> meta = metadata_lens(inputs.front(), b.cols(), b.rows());
      const PhotoOptics optics = meta ? meta->optics : read_photo_optics(inputs.front());
      // Why no focal length in pixels: what the EXIF held and what was missing to convert it.
      std::string lensfun_why = meta ? meta->lensfun_why : "the photo's metadata has no FocalLength";
      if (!meta && optics.focal_mm) {
        char mm[32];
        std::snprintf(mm, sizeof mm, "%.3g mm", *optics.focal_mm);
        lensfun_why = "FocalLength " + std::string(mm) +
                      " but no FocalLengthIn35mmFilm, and lensfun knows no crop factor of the camera '" + optics.make +
                      " " + optics.model + "' (its sensor size)";
      }
      const bool from_lensfun = meta && meta->source == "lensfun";
      const std::optional<OpticsLens> guess = meta ? std::optional<OpticsLens>(meta->lens) : std::nullopt;
      if (!guess) {
        // No focal length in the metadata (stripped by an app, a scan): a pinhole of the image's
        // diagonal (a normal lens) to start from; the lens step measures f from the balls' outlines.
        const double f = std::hypot(double(b.cols()), double(b.rows()));
        const LensModel lens = LensModel::pinhole(f, b.cols(), b.rows());
        lens.write(out);
        s = {{"source", "outlines"},
             {"model", lens.name()},
             {"intrinsics", lens.intrinsics()},
             {"focal_px", f},
             {"focal_from",
              "none: no usable focal length in the photos' metadata (FocalLengthIn35mmFilm, or "
              "FocalLength of a camera lensfun knows)"},
             {"camera", optics.make + " " + optics.model},
             {"lens", optics.lens},
             {"lensfun", lensfun_why},
             {"assumed",
              "a pinhole: principal point at the image centre, no distortion, the focal length from the "
              "balls' outlines (the lens step)"}};
        r.outputs = {out};
        r.summary = s;
        return;
      }
      guess->lens.write(out);
      s = {{"source", from_lensfun ? "lensfun" : "exif"},
           {"model", guess->lens.name()},
           {"intrinsics", guess->lens.intrinsics()},
           {"focal_px", guess->focal_px},
           {"focal_sigma_relative", guess->sigma_relative},
           {"focal_from", guess->source},
           {"camera", optics.make + " " + optics.model},
           {"lens", optics.lens},
           {"assumed", from_lensfun ? "lensfun's distortion profile of the lens, its centre at lensfun's"
                                    : "a pinhole: principal point at the image centre, no distortion"}};
      if (!from_lensfun) s["lensfun"] = lensfun_why;
      if (optics.focal_mm) s["focal_mm"] = *optics.focal_mm;
      if (optics.focal_35mm) s["focal_35mm"] = *optics.focal_35mm;
    } else if (settings["source"] != "chessboards") {
      const LensModel lens = LensModel::read(inputs.front());
      lens.write(out);
      s = {{"source", inputs.front().string()}, {"model", lens.name()}, {"intrinsics", lens.intrinsics()}};
    } else {
      std::vector<std::string> missed;
      Progress bar("calibrate", c.o.progress);
      const IntrinsicsProblem p = chessboard_problem(c.set, c.o.photoset, &missed, [&](double f) { bar.update(f); });
      bar.done();
      const std::vector<std::string> models = settings["models"];
      int chosen = 0;
      const std::vector<ModelScore> scores = cross_validate_models(p, models, &chosen);
      const IntrinsicsFit fit = fit_intrinsics(p, models[chosen]);
      fit.lens.write(out);
      nlohmann::json sc = nlohmann::json::array();
      for (const ModelScore& m : scores)
        sc.push_back({{"model", m.model}, {"held_out_rms_px", m.held_out_rms_px}, {"fit_rms_px", m.fit_rms_px}});
      s = {{"source", "chessboards"},
           {"model", models[chosen]},
           {"intrinsics", fit.lens.intrinsics()},
           {"rms_px", fit.rms_px},
           {"outliers", fit.outliers},
           {"boards_found", p.boards.size()},
           {"boards_missed", missed},
           {"models", sc}};
    }
    r.outputs = {out};
    r.summary = s;
  });
}

// ---- hdr: response once (from the view with the most brackets), then every view's merge.
// The stage swapped for given linear images (the truth of a synthetic capture, for the error
// budget): DIR/<view>_radiance.exr or DIR/<view>.exr per view, written as merged views with zero
// variance and no flags.
void step_given_radiance(Context& c) {
  std::vector<fs::path> inputs;
  for (const PhotoView& v : c.set.views) {
    const fs::path a = fs::path(c.o.radiance_dir) / (v.name + "_radiance.exr"),
                   b = fs::path(c.o.radiance_dir) / (v.name + ".exr");
    if (fs::is_regular_file(a))
      inputs.push_back(a);
    else if (fs::is_regular_file(b))
      inputs.push_back(b);
    else
      throw std::invalid_argument(c.o.radiance_dir + ": no " + a.filename().string() + " or " + b.filename().string());
  }
  run_step(c, "hdr", {{"response", "given radiance"}, {"radiance", c.o.radiance_dir}}, inputs, [&](StepRecord& r) {
    fs::create_directories(c.dir / "hdr");
    nlohmann::json views = nlohmann::json::array();
    for (std::size_t i = 0; i < c.set.views.size(); ++i) {
      const ViewImage img = read_view_image(inputs[i].string());
      MergedImage m;
      m.radiance = img.radiance;
      m.variance = cv::Mat::zeros(img.radiance.size(), CV_32FC3);
      m.flags = cv::Mat::zeros(img.radiance.size(), CV_8UC1);
      const fs::path exr = merged_path(c, c.set.views[i].name);
      write_merged_exr(exr.string(), m,
                       {{"version", RSIBR_VERSION},
                        {"view", c.set.views[i].name},
                        {"source", inputs[i].string()},
                        {"producer", "rsibr process (given radiance)"}});
      r.outputs.push_back(exr);
      views.push_back(
          {{"name", c.set.views[i].name}, {"brackets", 0}, {"clipped_fraction", 0.0}, {"ghost_fraction", 0.0}});
    }
    r.summary = {{"model", "given radiance (" + c.o.radiance_dir + ")"},
                 {"recovered_from", "-"},
                 {"curve", nlohmann::json::array()},
                 {"views", views}};
  });
}

void step_hdr(Context& c) {
  if (!c.o.radiance_dir.empty()) return step_given_radiance(c);
  std::vector<fs::path> inputs;
  for (const PhotoView& v : c.set.views)
    for (const BracketPhoto& b : v.brackets) inputs.push_back(b.file);
  // Vignetting (pipeline/vignetting_input.h): its inputs and the lens's principal point.
  for (const fs::path& f : vignetting_inputs(c.set, c.o.vignetting)) inputs.push_back(f);
  if (c.o.vignetting != "none") inputs.push_back(c.dir / "camera.cameramodel");
  // The camera's colour space (hdr/merged_colour.h): the option, else the photo set's; RAW views
  // are developed to linear Rec.709 (hdr/raw_image.h) whatever the photo set says.
  const std::string input_space = !c.o.input_colour_space.empty() ? c.o.input_colour_space : c.set.camera_colour_space;
  run_step(c, "hdr", {{"response", "auto"}, {"vignetting", c.o.vignetting}, {"input_colour_space", input_space}},
           inputs, [&](StepRecord& r) {
             fs::create_directories(c.dir / "hdr");
             std::vector<const PhotoView*> all;
             for (const PhotoView& v : c.set.views) all.push_back(&v);
             const PhotoSetResponse psr = recover_photo_set_response(all, RecoveryOptions{}, Alignment::automatic);
             const ResponseRecovery& rec = psr.recovery;
             const std::string from = psr.from.empty()
                                          ? std::string("none: one exposure per view, the sRGB response stated")
                                          : std::to_string(psr.from.size()) + " views (all with brackets)";
             const ResponseCurve& curve = rec.curve;
             nlohmann::json cands = nlohmann::json::array();
             for (const auto& k : rec.candidates)
               cands.push_back({{"model", k.model},
                                {"held_out_error", std::isfinite(k.held_out_error) ? nlohmann::json(k.held_out_error)
                                                                                   : nlohmann::json("rejected")}});
             const fs::path response = c.dir / "hdr" / "response.json";
             save_response(response, curve,
                           {{"camera", c.set.camera_name}, {"recovered_from", from}, {"recovery", recovery_json(rec)}});
             nlohmann::json plot = nlohmann::json::array();
             for (int k = 0; k <= 64; ++k) {
               const double z = double(k) * curve.max_code / 64;
               plot.push_back({z, curve.linear(0, z), curve.linear(1, z), curve.linear(2, z)});
             }
             r.outputs.push_back(response);
             nlohmann::json vignetting;
             const Vignetting vig = photo_set_vignetting(c.set, c.o.vignetting, curve,
                                                         LensModel::read(c.dir / "camera.cameramodel"), &vignetting);
             const fs::path vfile = c.dir / "hdr" / "vignetting.json";
             write_text_atomically(vfile, vignetting["model"].dump(2) + "\n");
             r.outputs.push_back(vfile);
             nlohmann::json views = nlohmann::json::array();
             Progress bar("hdr", c.o.progress);
             for (std::size_t i = 0; i < c.set.views.size(); ++i) {
               const PhotoView& v = c.set.views[i];
               ViewMergeSettings vs;
               vs.noise = psr.noise;
               vs.vignetting = &vig;
               vs.input_colour_space = c.o.input_colour_space;
               vs.camera_colour_space = c.set.camera_colour_space;
               ViewMerge vm = merge_view_radiance(v, curve, vs);
               const BracketSet& b = vm.brackets;
               const NoiseModel& noise = vm.noise;
               MergedImage& m = vm.image;
               const std::string& from = vm.input_colour_space;
               const fs::path exr = merged_path(c, v.name);
               write_merged_exr(exr.string(), m,
                                {{"version", RSIBR_VERSION},
                                 {"view", v.name},
                                 {"responseModel", curve.model},
                                 {"responseFile", "response.json (next to this file)"},
                                 {"colourSpace", working_space()},
                                 {"inputColourSpace", from.empty() ? working_space() : from},
                                 {"radianceUnit", "X/e: signal over saturation per relative exposure t*iso/100/N^2"},
                                 {"producer", "rsibr process (hdr step)"}});
               r.outputs.push_back(exr);
               const double px = double(m.radiance.total());
               nlohmann::json shifts = nlohmann::json::array(), bracket_names = nlohmann::json::array();
               for (const cv::Point& s : vm.shifts) shifts.push_back({s.x, s.y});
               for (const std::string& f : b.files) bracket_names.push_back(fs::path(f).filename().string());
               views.push_back({{"name", v.name},
                                {"brackets", b.size()},
                                {"clipped_fraction", m.clipped / px},
                                {"clipped_pixels", m.clipped},
                                {"ghost_fraction", m.ghost / px},
                                {"noise_read", noise.read},
                                {"noise_shot", noise.shot},
                                {"alignment_shifts", shifts},
                                {"alignment_rotations_deg", vm.alignment.rotation_deg},
                                {"alignment_beyond_search", vm.alignment.beyond_search},
                                {"alignment_mismatch_after", vm.alignment.mismatch_after},
                                {"bracket_files", bracket_names},
                                {"sizes_fitted", b.fitted_sizes}});
               bar.update(double(i + 1) / double(c.set.views.size()));
             }
             bar.done();
             r.summary = {{"model", curve.model},
                          {"recovered_from", from},
                          {"candidates", cands},
                          {"recovery", recovery_json(rec)},
                          {"curve", plot},
                          {"max_code", curve.max_code},
                          {"views", views},
                          {"vignetting", vignetting},
                          {"camera", c.set.camera_name},
                          {"input_colour_space", input_space.empty() ? working_space() : input_space},
                          {"colour_space", working_space()}};
           });
}

// The bracket of a view that its registration left furthest from the middle one (the largest
// disagreement of the threshold bitmaps after it), for an error about a ghost: "FILE (moved X,Y px;
// P% of its bitmap disagrees)", or "" when the hdr step's summary does not tell.
std::string suspect_bracket(const PhotoView& v, const nlohmann::json& hdr) {
  if (!hdr.is_object() || !hdr.contains("views")) return "";
  for (const auto& vj : hdr["views"]) {
    if (vj.value("name", "") != v.name || !vj.contains("alignment_mismatch_after")) continue;
    // In the merge's order (by exposure), the middle one the reference.
    const auto& m = vj["alignment_mismatch_after"];
    const auto& shifts = vj["alignment_shifts"];
    const auto& files = vj.value("bracket_files", nlohmann::json::array());
    const std::size_t n = std::min(m.size(), files.size());
    std::size_t worst = n;
    for (std::size_t j = 0; j < n; ++j)
      if (j != n / 2 && (worst == n || m[j].get<double>() > m[worst].get<double>())) worst = j;
    if (worst == n) return "";
    std::string text = files[worst].get<std::string>();
    if (worst < shifts.size())
      text += " (moved " + std::to_string(shifts[worst][0].get<int>()) + "," +
              std::to_string(shifts[worst][1].get<int>()) + " px; " +
              std::to_string(int(std::lround(100 * m[worst].get<double>()))) + "% of its bitmap disagrees)";
    return text;
  }
  return "";
}

// ---- lens: the calibrated lens, its focal length refined from the balls' outlines when it came
// from the photos' metadata (pipeline/lens_step.h) -> DIR/lens.cameramodel, the lens of every
// later step.
void step_lens(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "camera.cameramodel");
  LensStep s;
  s.calibrated = c.dir / "camera.cameramodel";
  s.source = recorded(c, "calibrate", "source").get<std::string>();
  // A focal length from the metadata has a prior sigma; a lens from boards or a file has none.
  if (s.source == "exif" || s.source == "lensfun")
    s.prior_sigma_relative = recorded(c, "calibrate", "focal_sigma_relative").get<double>();
  if (s.source == "outlines") s.metadata_note = recorded(c, "calibrate", "lensfun").get<std::string>();
  s.refine = c.o.self_calibrate;
  s.balls = listed_balls(c.set);
  s.out = c.dir / "lens.cameramodel";
  s.pictures = c.dir / "balls";
  const std::vector<BallOverride> overrides = parse_ball_overrides(c.o.ball_overrides, c.set);
  nlohmann::json given = nlohmann::json::array();
  const nlohmann::json& hdr = c.result.summary["hdr"];
  for (const PhotoView& v : c.set.views) {
    s.views.push_back(v.name);
    s.merged.push_back(merged_path(c, v.name));
    s.suspect_bracket.push_back(suspect_bracket(v, hdr));
    s.given.emplace_back();
    for (const ListedBall& b : s.balls) {
      s.given.back().push_back(find_override(overrides, v.name, b.name));
      if (const auto& g = s.given.back().back())
        given.push_back({v.name, b.name, g->centre_px.x(), g->centre_px.y(), g->radius_px});
    }
  }
  nlohmann::json balls = nlohmann::json::array();
  for (const ListedBall& b : s.balls) balls.push_back({b.name, to_string(b.kind)});
  const nlohmann::json settings = {
      {"refine", s.refine}, {"source", s.source},    {"prior_sigma_relative", s.prior_sigma_relative},
      {"balls", balls},     {"crops", "far camera"}, {"given", given}};
  run_step(c, "lens", settings, inputs, [&](StepRecord& r) {
    r.summary = run_lens_step(s);
    r.outputs = {s.out};
    for (const auto& name : r.summary.value("candidates_pictures", nlohmann::json::array()))
      r.outputs.push_back(s.pictures / name.get<std::string>());
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

// ---- orient: world_from_cam per view, solved from the chrome ball's reflected features
// (calib/orientation/view_orientation.h; world +Y up: estimated from the views, or `up` given in the first
// camera's frame), or given (--poses: the file's chrome balls, refined here by the features with
// the rotations held when the file has none; a first-view file levelled by the estimated up).
nlohmann::json world_up_json(const WorldUp& w) {
  return {{"up_in_first_camera", {w.up.x(), w.up.y(), w.up.z()}},
          {"sigma_deg", w.sigma_deg},
          {"roll_sigma_deg", w.roll_sigma_deg},
          {"roll_sigma_estimated", w.roll_sigma_estimated},
          {"roll_deg", w.roll_deg},
          {"tilt_from_first_camera_deg", w.tilt_from_first_deg},
          {"lines", w.lines}};
}

void step_orient(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "lens.cameramodel");
  if (!c.o.points.empty()) {
    if (!c.o.poses.empty()) throw std::invalid_argument("--points: not with --poses (the poses are given)");
    inputs.push_back(c.o.points);
  }
  if (!c.o.poses.empty()) {
    inputs.push_back(c.o.poses);
    const PoseSet given = read_given_poses(c.o.poses);
    for (const PhotoView& v : c.set.views)
      if (!given.find(v.name)) throw std::invalid_argument(c.o.poses + ": no pose for view '" + v.name + "'");
  }
  const std::vector<BallOverride> overrides = parse_ball_overrides(c.o.ball_overrides, c.set);
  const std::vector<ListedBall> listed = listed_balls(c.set);
  std::vector<std::optional<BallGuess>> given_chrome;
  nlohmann::json chrome_overrides = nlohmann::json::array();
  // The chrome ball given by hand in a view (the first listed chrome ball's --ball).
  for (const PhotoView& v : c.set.views) {
    std::optional<BallGuess> g;
    for (const BallSpec& b : c.set.balls)
      if (b.kind == BallKind::chrome && !g) g = find_override(overrides, v.name, b.name);
    if (g) chrome_overrides.push_back({v.name, g->centre_px.x(), g->centre_px.y(), g->radius_px});
    given_chrome.push_back(g);
  }
  nlohmann::json balls = nlohmann::json::array();
  for (const BallSpec& b : c.set.balls) balls.push_back({b.name, to_string(b.kind), b.diameter_m.value_or(0.0)});
  const nlohmann::json settings = {{"source", c.o.poses.empty() ? "solve" : "given"},
                                   {"up", c.o.up ? nlohmann::json{c.o.up->x(), c.o.up->y(), c.o.up->z()}
                                                 : nlohmann::json(c.o.estimate_up ? "auto" : "none")},
                                   {"balls", balls},
                                   {"chrome_overrides", chrome_overrides}};
  run_step(c, "orient", settings, inputs, [&](StepRecord& r) {
    PoseSet poses;
    std::string source;
    nlohmann::json solve, left_out = nlohmann::json::array(), notes = nlohmann::json::array(), up = nullptr;
    const LensModel lens = LensModel::read(c.dir / "lens.cameramodel");
    std::vector<std::string> names;
    std::vector<ViewImage> images;
    auto load_images = [&] {
      for (const PhotoView& v : c.set.views) {
        names.push_back(v.name);
        images.push_back(read_merged_view(c, v, lens));
      }
    };
    ViewOrientationOptions vo;
    vo.listed = listed;
    vo.given_chrome = given_chrome;
    if (!c.o.points.empty()) vo.points = read_point_pairs(c.o.points);
    ViewOrientationReport report;
    if (!c.o.poses.empty()) {
      poses = read_given_poses(c.o.poses);
      source = "given (" + c.o.poses + ")";
      PoseSet ordered;
      ordered.gauge = poses.gauge;
      for (const PhotoView& v : c.set.views) ordered.views.push_back(*poses.find(v.name));
      poses = ordered;
      bool all_balls = true;
      for (const ViewPose& p : poses.views) all_balls = all_balls && p.ball.has_value();
      if (!all_balls) {
        // The chrome balls refined by the features with the file's rotations held.
        load_images();
        for (const ViewPose& p : poses.views) vo.known_world_from_cam.push_back(p.world_from_cam);
        const PoseSet refined = orient_views(names, images, lens, vo, &report);
        for (ViewPose& p : poses.views)
          if (!p.ball)
            if (const ViewPose* q = refined.find(p.name)) p.ball = q->ball;
        source += ", chrome balls refined by the features with the rotations held";
        for (const std::string& w : report.left_out) left_out.push_back(w);
      }
      if (poses.gauge == "first-view" && !c.o.up && c.o.estimate_up) {
        up = world_up_json(level_pose_set(poses));
        source += ", levelled by the estimated up";
      }
    } else {
      load_images();
      vo.up = c.o.up;
      vo.estimate_up = c.o.estimate_up;
      // Per pair, the features that tied the views (or failed to): DIR/orient/A--B.png.
      const auto pair_pictures = [&] {
        std::vector<fs::path> files;
        for (const PairOrientation& p : report.pairs) {
          const auto image = [&](const std::string& name) -> const cv::Mat& {
            return images[std::size_t(std::find(names.begin(), names.end(), name) - names.begin())].radiance;
          };
          fs::create_directories(c.dir / "orient");
          files.push_back(file_in_folder(c.dir / "orient", p.a + "--" + p.b + ".png"));
          write_pair_matches_picture(files.back(), image(p.a), image(p.b), p);
        }
        return files;
      };
      try {
        poses = orient_views(names, images, lens, vo, &report);
      } catch (const std::exception&) {
        // What the solve saw before it stopped, for steps/orient.failed.json and the pictures.
        nlohmann::json pictures = nlohmann::json::array();
        for (const fs::path& f : pair_pictures()) pictures.push_back(fs::relative(f, c.dir).string());
        r.summary = {{"left_out", report.left_out},
                     {"notes", report.notes},
                     {"solve",
                      {{"features", report.features},
                       {"pairs", pair_orientation_json(report.pairs)},
                       {"pair_pictures", pictures}}}};
        throw;
      }
      nlohmann::json pictures = nlohmann::json::array();
      for (const fs::path& f : pair_pictures()) {
        r.outputs.push_back(f);
        pictures.push_back(fs::relative(f, c.dir).string());
      }
      source = "solved (chrome-ball features)";
      solve = {{"tracks", report.tracks},
               {"observations", report.observations},
               {"inliers", report.inliers},
               {"rms_sigmas", report.rms_sigmas},
               {"features", report.features},
               {"tracks_relocated", report.track_refinement.tracks_refined},
               {"rig_disagreement_radii", report.rig_disagreement},
               {"pairs", pair_orientation_json(report.pairs)},
               {"pair_pictures", pictures}};
      std::vector<std::string> suspects;
      for (std::size_t v = 0; v < report.rig_suspect.size(); ++v)
        if (report.rig_suspect[v]) suspects.push_back(report.names[v]);
      solve["left_out_of_up"] = suspects;
      for (const std::string& w : report.left_out) left_out.push_back(w);
      for (const std::string& w : report.notes) notes.push_back(w);
      if (report.world_up) up = world_up_json(*report.world_up);
    }
    // In the set's order, only its views (those left out have no pose).
    PoseSet ordered;
    ordered.gauge = poses.gauge;
    for (const PhotoView& v : c.set.views)
      if (const ViewPose* p = poses.find(v.name)) ordered.views.push_back(*p);
    const fs::path out = c.dir / "poses.yaml";
    write_pose_file(out.string(), ordered);
    nlohmann::json views = nlohmann::json::array();
    for (const ViewPose& p : ordered.views) {
      const Vec3 forward = p.world_from_cam.col(2);
      nlohmann::json vj = {
          {"name", p.name}, {"sigma_deg", p.sigma_deg}, {"forward", {forward.x(), forward.y(), forward.z()}}};
      if (p.ball) {
        const Vec2 cp = lens.project(p.ball->axis);
        vj["chrome_centre_px"] = {cp.x(), cp.y()};
      }
      views.push_back(vj);
    }
    r.outputs.push_back(out);
    r.summary = {{"source", source},     {"gauge", ordered.gauge}, {"views", views}, {"solve", solve},
                 {"left_out", left_out}, {"notes", notes},         {"world_up", up}};
  });
}

// ---- extract: every listed ball of every view, in the world frame (pipeline/extract_step.h) ->
// DIR/maps/captured-<ball>.exr and each map's mask in DIR/masks/.
void step_extract(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "lens.cameramodel");
  inputs.push_back(c.dir / "poses.yaml");
  const std::vector<BallOverride> overrides = parse_ball_overrides(c.o.ball_overrides, c.set);
  nlohmann::json balls = nlohmann::json::array(), given = nlohmann::json::array();
  for (const BallSpec& b : c.set.balls) balls.push_back({b.name, to_string(b.kind), b.diameter_m.value_or(0.0)});
  for (const BallOverride& o : overrides)
    given.push_back({o.view, o.ball, o.guess.centre_px.x(), o.guess.centre_px.y(), o.guess.radius_px});
  nlohmann::json settings = {{"map_size", c.o.map_size}, {"balls", balls}, {"given", given}};
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
    s.balls = listed_balls(c.set);
    for (const PhotoView& v : c.set.views) {
      s.views.push_back(v.name);
      s.given.emplace_back();
      for (const ListedBall& b : s.balls) s.given.back().push_back(find_override(overrides, v.name, b.name));
    }
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

// ---- probe: the chrome maps blended.
void step_probe(Context& c) {
  const int width = probe_width(c);
  const auto chrome = balls_of(c, BallKind::chrome);
  if (chrome.empty()) throw std::invalid_argument(c.o.photoset + ": balls: no chrome ball (the probe needs one)");
  std::vector<fs::path> inputs;
  for (const BallSpec* b : chrome) inputs.push_back(captured_path(c, *b));
  if (!c.o.probe_file.empty()) {
    // The stage swapped for a given environment (the truth, for the error budget): resampled
    // (area-weighted, core/resample.h) to the probe's lat-long size.
    run_step(c, "probe", {{"width", width}, {"given", c.o.probe_file}}, {c.o.probe_file}, [&](StepRecord& r) {
      EnvMap env = resample(read_environment(c.o.probe_file), Layout(LayoutKind::LatLong, width, width / 2));
      env.attributes["producer"] = "rsibr process (given probe " + fs::path(c.o.probe_file).filename().string() + ")";
      const fs::path out = c.dir / "probe-measured.exr";
      write_environment(out.string(), env);
      r.outputs = {out};
      r.summary = {{"views", 0}, {"width", width}, {"covered_fraction", 1.0}, {"fresnel", "given: " + c.o.probe_file}};
    });
    return;
  }
  run_step(c, "probe", {{"width", width}, {"fresnel", c.o.chrome_fresnel}}, inputs, [&](StepRecord& r) {
    MapSet all;
    for (const fs::path& p : inputs)
      for (MapView& v : read_map_set(p.string()).views) all.views.push_back(std::move(v));
    ProbeOptions po;
    po.width = width;
    const auto fresnel = chrome_fresnel_from_spec(c.o.chrome_fresnel, "--chrome-fresnel");
    po.fresnel = fresnel.get();
    Probe p = assemble_probe(all, po);
    // A chrome ball sees most of the sphere from one view (all but the cone behind it); a probe
    // that saw almost nothing means a lens or a ball that is wrong, never a usable probe.
    if (!(p.covered_fraction >= 0.1))
      throw std::runtime_error(
          "the chrome maps saw " + std::to_string(100 * p.covered_fraction).substr(0, 4) +
          "% of the sphere (a chrome ball sees most of it): the lens (lens.cameramodel, see the lens step) or the "
          "chrome ball is wrong; give the lens with --lens FILE or the ball with --ball VIEW:BALL=X,Y,R");
    p.env.attributes["views"] = std::to_string(all.views.size());
    p.env.attributes["producer"] = "rsibr process (probe step)";
    p.env.attributes["version"] = RSIBR_VERSION;
    if (fresnel) p.env.attributes["fresnel"] = fresnel->spec();
    const fs::path out = c.dir / "probe-measured.exr";
    write_environment(out.string(), p.env);
    r.outputs = {out};
    // Seen well: a summed confidence of at least one half (one view's centre to mid-disc; behind
    // the ball a lone view sees only its stretched rim, where the confidence fades to 0).
    double well = 0, all_sa = 0;
    for (int y = 0; y < p.weight.rows; ++y) {
      const double sa = std::cos((0.5 - (y + 0.5) / p.weight.rows) * kPiD);
      for (int x = 0; x < p.weight.cols; ++x) {
        all_sa += sa;
        if (p.weight.at<float>(y, x) >= 0.5f) well += sa;
      }
    }
    r.summary = {{"views", all.views.size()},
                 {"width", width},
                 {"memory_mb", double(probe_bytes(width)) / (1 << 20)},
                 {"covered_fraction", p.covered_fraction},
                 {"well_seen_fraction", all_sa > 0 ? well / all_sa : 0.0},
                 {"clipped_fraction", p.clipped_fraction},
                 {"fresnel", fresnel ? fresnel->spec() : "none (the probe holds F L)"}};
  });
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

// ---- bake: computed maps of the grey balls from the probe, at the captured views.
void step_bake(Context& c) {
  std::vector<fs::path> inputs = {c.dir / "probe.exr"};
  const auto greys = balls_of(c, BallKind::grey);
  for (const BallSpec* b : greys) inputs.push_back(captured_path(c, *b));
  nlohmann::json settings = {
      {"albedo", c.o.grey_albedo}, {"method", c.o.bake_method}, {"samples", c.o.bake_samples}, {"seed", c.o.seed}};
  if (c.o.bake_max_error > 0)
    settings = {{"albedo", c.o.grey_albedo}, {"max_error", c.o.bake_max_error}, {"seed", c.o.seed}};
  run_step(c, "bake", settings, inputs, [&](StepRecord& r) {
    const EnvMap probe = read_environment((c.dir / "probe.exr").string());
    std::ostringstream spec;
    spec << std::setprecision(9) << "{type: lambert, albedo: [" << c.o.grey_albedo << ", " << c.o.grey_albedo << ", "
         << c.o.grey_albedo << "]}";
    const auto brdf = parse_brdf(spec.str());
    std::string method = c.o.bake_method;
    MapSetBakeOptions bo;
    bo.integrator.samples = c.o.bake_samples;
    nlohmann::json planned;
    // Planned with the bake's own seed: a filtered-importance bake's error depends on it.
    if (c.o.bake_max_error > 0) {
      const IntegratorPlan plan =
          plan_integrator(probe, *brdf, c.o.bake_max_error, default_integrator_settings(), c.o.seed);
      if (!plan.chosen)
        throw std::runtime_error("no integrator is predicted to reach --max-error " +
                                 std::to_string(c.o.bake_max_error) + " on probe.exr");
      method = plan.chosen->setting.method;
      bo.integrator.samples = std::max(1, plan.chosen->setting.samples);
      bo.integrator.reference_width = plan.chosen->setting.reference_width;
      planned = plan.to_json();
      if (c.o.log)
        c.o.log("bake: planned " + plan.chosen->setting.label() + " (" + std::to_string(100 * plan.chosen->error) +
                "% at the pilot texels)");
    }
    const auto integrator = make_integrator(method, probe);
    bo.integrator.seed = c.o.seed;
    bo.environment_name = "probe.exr";
    nlohmann::json balls = nlohmann::json::array();
    for (const BallSpec* b : greys) {
      const MapSet captured = read_map_set(captured_path(c, *b).string());
      // At the captured maps' own frames and size, so the comparison is texel for texel.
      std::vector<BakeFrame> frames;
      for (const MapView& cv : captured.views) frames.push_back({cv.view, cv.world_from_view});
      bo.res = captured.width();
      MapSet computed = bake_map_set(*brdf, *integrator, frames, bo);
      for (std::size_t i = 0; i < computed.views.size(); ++i) {
        computed.views[i].image = captured.views[i].image;
      }
      const fs::path out = computed_path(c, *b);
      write_map_set(out.string(), computed);
      r.outputs.push_back(out);
      balls.push_back({{"ball", b->name}, {"views", computed.views.size()}});
    }
    r.summary = {{"material", brdf->spec()}, {"balls", balls}, {"method", method}};
    if (!planned.is_null()) r.summary["plan"] = planned;
  });
}

// ---- compare: captured against computed, per grey ball.
void step_compare(Context& c) {
  const auto greys = balls_of(c, BallKind::grey);
  std::vector<fs::path> inputs;
  for (const BallSpec* b : greys) inputs.push_back(captured_path(c, *b)), inputs.push_back(computed_path(c, *b));
  run_step(c, "compare", nlohmann::json::object(), inputs, [&](StepRecord& r) {
    nlohmann::json balls = nlohmann::json::array();
    for (const BallSpec* b : greys) {
      MapSet captured = read_map_set(captured_path(c, *b).string());
      MapSet computed = read_map_set(computed_path(c, *b).string());
      // Views whose ball has no trusted texel (hidden behind another ball, or not found) cannot be
      // compared: left out and listed (the bake made one computed view per captured one, in order).
      std::vector<std::string> untrusted;
      if (captured.views.size() == computed.views.size()) {
        MapSet a, bset;
        for (std::size_t i = 0; i < captured.views.size(); ++i) {
          if (cv::countNonZero(captured.views[i].confidence > 0) == 0) {
            untrusted.push_back(!captured.views[i].image.empty() ? captured.views[i].image
                                                                 : "view." + std::to_string(i));
            continue;
          }
          a.views.push_back(std::move(captured.views[i]));
          bset.views.push_back(std::move(computed.views[i]));
        }
        if (a.views.empty()) {
          balls.push_back({{"ball", b->name}, {"views", nlohmann::json::array()}, {"untrusted_views", untrusted}});
          continue;
        }
        captured = std::move(a), computed = std::move(bset);
      }
      CompareOptions co;
      co.name_a = captured_path(c, *b).string();
      co.name_b = computed_path(c, *b).string();
      const Comparison cmp = compare_map_sets(captured, computed, co);
      // The same JSON and pictures as rsibr compare (compare/comparison_report.h), plus the ball,
      // each view's image and the views left out.
      const ComparisonImages images = comparison_images(cmp);
      nlohmann::json bj = comparison_json(cmp, images, true);
      FolderContents files;
      for (std::size_t i = 0; i < cmp.pairs.size(); ++i) {
        const PairComparison& p = cmp.pairs[i];
        const std::string image = !captured.views[p.index_a].image.empty() ? captured.views[p.index_a].image : p.name;
        const std::string name = p.name + ".png";
        files[name] =
            png_bytes(comparison_panel(cmp, images, i, b->name + " " + image, "captured x gains", "computed"), name);
        bj["views"][i]["image"] = image;
        bj["views"][i]["picture"] = name;
      }
      const fs::path folder = c.dir / "compare" / b->name;
      fs::create_directories(folder.parent_path());
      write_folder_atomically(folder, files);
      for (const auto& [name, bytes] : files) r.outputs.push_back(folder / name);
      bj["ball"] = b->name;
      bj["folder"] = "compare/" + b->name;
      bj["untrusted_views"] = untrusted;
      bj["heat_max_stops"] = images.heat_max;
      bj["log_epsilon"] = cmp.settings.log_epsilon;
      balls.push_back(bj);
    }
    r.summary = {{"balls", balls}};
  });
}

// ---- render: a turntable of a mesh lit by the probe, through the runtime.
void step_render(Context& c) {
  std::vector<fs::path> inputs = {c.dir / "probe.exr"};
  if (!c.o.mesh.empty()) inputs.push_back(c.o.mesh);
  const nlohmann::json settings = {{"brdf", c.o.render_brdf}, {"res", c.o.render_views_res},
                                   {"frames", c.o.turntable}, {"size", {c.o.render_width, c.o.render_height}},
                                   {"seed", c.o.seed},        {"mesh", c.o.mesh.empty() ? "built-in torus" : c.o.mesh}};
  run_step(c, "render", settings, inputs, [&](StepRecord& r) {
    const EnvMap probe = read_environment((c.dir / "probe.exr").string());
    const auto brdf = parse_brdf(c.o.render_brdf);
    // The render's maps are render_views_res texels of a glossy lobe: a probe wider than 512 adds
    // nothing to them but the integrator's MIP pyramid (7 s of 9 for a 1472-wide probe on 2 cores).
    // Area sampling keeps the energy; the full probe stays the background.
    std::optional<EnvMap> smaller;
    if (probe.layout.width() > 512) {
      ResampleOptions rs;
      rs.supersampling = 1;
      smaller = resample(probe, Layout(LayoutKind::LatLong, 512, 256), rs);
    }
    const auto integrator = make_integrator("fis", smaller ? *smaller : probe);
    MapSetBakeOptions bo;
    bo.res = c.o.render_views_res;
    bo.integrator.samples = 32;
    bo.integrator.seed = c.o.seed;
    bo.environment_name = "probe.exr";
    const MapSet maps = bake_map_set(*brdf, *integrator, ViewSet::named("icosa"), bo);
    const fs::path folder = c.dir / "render";
    fs::create_directories(folder);
    write_map_set((folder / "maps.exr").string(), maps);
    const Mesh mesh = c.o.mesh.empty() ? torus_mesh() : load_mesh(c.o.mesh);
    RenderOptions ro;
    ro.environment = &probe;
    const Renderer renderer(mesh, {&maps}, ro);
    const Eigen::AlignedBox3f box = mesh.bounds();
    const Vec3 pivot = box.center().cast<double>();
    const Camera first = frame_bounds(box, Vec3(0, -0.4, -1), Vec3(0, 1, 0), 40, c.o.render_width, c.o.render_height);
    // Display exposure: the probe's median at mid-grey (the object reflects the environment).
    const float stops = preview_exposure(probe.pixels);
    FolderContents files;
    double seconds = 0;
    Progress bar("render", c.o.progress);
    for (int k = 0; k < c.o.turntable; ++k) {
      RenderStats stats;
      const cv::Mat rgba = renderer.render(orbit(first, pivot, Vec3(0, 1, 0), k, c.o.turntable), &stats);
      seconds += stats.seconds;
      std::ostringstream name;
      name << "frame_" << std::setw(2) << std::setfill('0') << k << ".png";
      files[name.str()] = png_bytes(display_encode(rgba, stops), name.str());
      bar.update(double(k + 1) / c.o.turntable);
    }
    bar.done();
    write_folder_atomically(folder, files);
    r.outputs.push_back(folder / "maps.exr");
    for (const auto& [name, bytes] : files) r.outputs.push_back(folder / name);
    r.summary = {{"mesh", c.o.mesh.empty() ? "built-in torus" : c.o.mesh},
                 {"triangles", mesh.triangles.size()},
                 {"material", brdf->spec()},
                 {"frames", c.o.turntable},
                 {"seconds_per_frame", seconds / c.o.turntable},
                 {"display_exposure_stops", stops}};
  });
}

}  // namespace

const std::vector<std::string>& process_steps() {
  static const std::vector<std::string> steps = {"calibrate", "hdr",  "lens",    "orient", "extract", "probe",
                                                 "sources",   "bake", "compare", "render", "report"};
  return steps;
}

ProcessResult run_process(const ProcessOptions& o) {
  for (const std::string& f : o.force)
    if (f != "all" && std::find(process_steps().begin(), process_steps().end(), f) == process_steps().end())
      throw std::invalid_argument("--force '" + f +
                                  "': not a step (calibrate, hdr, lens, orient, extract, probe, sources, "
                                  "bake, compare, render, report, all)");
  if (!o.lens.empty() && !fs::is_regular_file(o.lens)) throw std::invalid_argument(o.lens + ": no such file");
  if (!o.mesh.empty() && !fs::is_regular_file(o.mesh)) throw std::invalid_argument(o.mesh + ": no such file");
  if (!o.probe_file.empty() && !fs::is_regular_file(o.probe_file))
    throw std::invalid_argument(o.probe_file + ": no such file");
  if (!o.radiance_dir.empty() && !fs::is_directory(o.radiance_dir))
    throw std::invalid_argument(o.radiance_dir + ": no such folder");
  if (!o.poses.empty()) read_given_poses(o.poses);  // errors before any work
  if (o.vignetting != "auto" && o.vignetting != "none") {
    if (!fs::is_regular_file(o.vignetting)) throw std::invalid_argument(o.vignetting + ": no such file (--vignetting)");
    photo_set_vignetting(PhotoSet{}, o.vignetting, ResponseCurve::identity(255), LensModel::pinhole(100, 64, 64),
                         nullptr);
  }
  if (o.up && !(o.up->norm() > 0 && o.up->allFinite()))
    throw std::invalid_argument("--up: expected a non-zero direction");
  if (!o.input_colour_space.empty() && o.input_colour_space != working_space()) {
    try {
      colour_conversion_matrix(o.input_colour_space, working_space());  // errors before any work
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(std::string("--input-colorspace: ") + e.what());
    }
  }
  parse_brdf(o.render_brdf);
  chrome_fresnel_from_spec(o.chrome_fresnel, "--chrome-fresnel");  // errors before any work
  if (!o.glossy_brdf.empty()) {
    try {
      parse_brdf(o.glossy_brdf);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--glossy-brdf: ") + e.what());
    }
  }
  ProcessResult result;
  Context c{o, fs::absolute(o.out).lexically_normal(), load_photo_set(o.photoset), result};
  if (c.set.views.empty()) throw std::invalid_argument(o.photoset + ": views: none");
  parse_ball_overrides(o.ball_overrides, c.set);  // errors before any work
  if (o.input_colour_space.empty() && !c.set.camera_colour_space.empty() &&
      c.set.camera_colour_space != working_space()) {
    try {
      colour_conversion_matrix(c.set.camera_colour_space, working_space());
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(o.photoset + ": camera.colour_space: " + e.what());
    }
  }
  if (fs::exists(c.dir) && !fs::is_directory(c.dir)) throw std::invalid_argument(o.out.string() + ": not a folder");
  if (!fs::is_directory(c.dir.parent_path()))
    throw std::invalid_argument(o.out.string() + ": its parent folder does not exist");
  // No output may land on an input (the photo folder itself must not be DIR).
  if (fs::exists(c.dir) && fs::equivalent(c.dir, c.set.folder))
    throw std::invalid_argument(o.out.string() + ": is the photo set's folder; choose another output folder");
  fs::create_directories(c.dir);

  try {
    step_calibrate(c);
    step_hdr(c);
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
