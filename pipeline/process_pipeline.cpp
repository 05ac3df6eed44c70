#include "pipeline/process_pipeline.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "calib/ball_locator.h"
#include "calib/intrinsics.h"
#include "calib/probe.h"
#include "calib/sphere_map_extraction.h"
#include "calib/view_image.h"
#include "calib/view_orientation.h"
#include "calib/pose_file.h"
#include "core/photo_set.h"
#include "core/atomic_file.h"
#include "core/atomic_folder.h"
#include "core/camera.h"
#include "core/colour.h"
#include "core/compare_pictures.h"
#include "core/exr_io.h"
#include "core/lens_model.h"
#include "core/map_compare.h"
#include "core/map_set.h"
#include "core/mesh.h"
#include "core/progress.h"
#include "core/resample.h"
#include "core/view_set.h"
#include "hdr/bracket_set.h"
#include "hdr/merge.h"
#include "hdr/merged_exr.h"
#include "hdr/noise_model.h"
#include "hdr/photo_set_merge.h"
#include "hdr/response_recovery.h"
#include "pipeline/chessboard_problem.h"
#include "pipeline/html_report.h"
#include "pipeline/pose_input.h"
#include "pipeline/step_record.h"
#include "pipeline/torus_mesh.h"
#include "runtime/renderer.h"

#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
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

std::vector<unsigned char> png_bytes(const cv::Mat& bgr, const std::string& name) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", bgr, bytes)) throw std::runtime_error(name + ": cannot encode the PNG");
  return bytes;
}

nlohmann::json metrics_json(const ErrorMetrics& m) {
  return {{"relative_rms", m.relative_rms}, {"log_rms_stops", m.log_rms_stops}, {"psnr_db", m.psnr_db},
          {"mean_a", m.mean_a}, {"mean_b", m.mean_b}};
}

// Runs `body` unless the step is up to date; body fills outputs and summary.
void run_step(Context& c, const std::string& step, const nlohmann::json& settings, const std::vector<fs::path>& inputs,
              const std::function<void(StepRecord&)>& body) {
  const bool forced = std::find(c.o.force.begin(), c.o.force.end(), step) != c.o.force.end() ||
                      std::find(c.o.force.begin(), c.o.force.end(), "all") != c.o.force.end();
  std::string reason = forced ? "forced" : step_stale_reason(c.dir, step, settings, inputs);
  StepOutcome outcome;
  outcome.step = step;
  if (reason.empty()) {
    const StepRecord old = read_step_record(c.dir, step);
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
  try {
    body(r);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(step + ": " + e.what());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_step_record(c.dir, r);
  outcome.ran = true;
  outcome.reason = reason;
  outcome.seconds = outcome.recorded_seconds = r.seconds;
  c.result.summary[step] = r.summary;
  c.result.steps.push_back(outcome);
}

std::vector<fs::path> hdr_files(const Context& c) {
  std::vector<fs::path> files;
  for (const PhotoView& v : c.set.views) files.push_back(c.dir / "hdr" / (v.name + ".exr"));
  return files;
}

std::vector<const BallSpec*> balls_of(const Context& c, BallKind kind) {
  std::vector<const BallSpec*> out;
  for (const BallSpec& b : c.set.balls)
    if (b.kind == kind) out.push_back(&b);
  return out;
}

fs::path captured_path(const Context& c, const BallSpec& b) { return c.dir / "maps" / ("captured-" + b.name + ".exr"); }
fs::path computed_path(const Context& c, const BallSpec& b) { return c.dir / "maps" / ("computed-" + b.name + ".exr"); }

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
    throw std::invalid_argument(c.o.photoset + ": no chessboards and no camera model; give the lens with --lens FILE");
  }
  run_step(c, "calibrate", settings, inputs, [&](StepRecord& r) {
    nlohmann::json s;
    if (settings["source"] != "chessboards") {
      const LensModel lens = LensModel::read(inputs.front());
      lens.write(out);
      s = {{"source", inputs.front().string()}, {"model", lens.name()}, {"intrinsics", lens.intrinsics()}};
    } else {
      std::vector<std::string> missed;
      Progress bar("calibrate", c.o.progress);
      const IntrinsicsProblem p =
          chessboard_problem(c.set, c.o.photoset, &missed, [&](double f) { bar.update(f); });
      bar.done();
      const std::vector<std::string> models = settings["models"];
      int chosen = 0;
      const std::vector<ModelScore> scores = cross_validate_models(p, models, &chosen);
      const IntrinsicsFit fit = fit_intrinsics(p, models[chosen]);
      fit.lens.write(out);
      nlohmann::json sc = nlohmann::json::array();
      for (const ModelScore& m : scores)
        sc.push_back({{"model", m.model}, {"held_out_rms_px", m.held_out_rms_px}, {"fit_rms_px", m.fit_rms_px}});
      s = {{"source", "chessboards"}, {"model", models[chosen]}, {"intrinsics", fit.lens.intrinsics()},
           {"rms_px", fit.rms_px}, {"outliers", fit.outliers}, {"boards_found", p.boards.size()},
           {"boards_missed", missed}, {"models", sc}};
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
    const fs::path a = fs::path(c.o.radiance_dir) / (v.name + "_radiance.exr"), b = fs::path(c.o.radiance_dir) / (v.name + ".exr");
    if (fs::is_regular_file(a)) inputs.push_back(a);
    else if (fs::is_regular_file(b)) inputs.push_back(b);
    else throw std::invalid_argument(c.o.radiance_dir + ": no " + a.filename().string() + " or " + b.filename().string());
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
      const fs::path exr = c.dir / "hdr" / (c.set.views[i].name + ".exr");
      write_merged_exr(exr.string(), m, {{"version", RSIBR_VERSION}, {"view", c.set.views[i].name},
                                          {"source", inputs[i].string()}, {"producer", "rsibr process (given radiance)"}});
      r.outputs.push_back(exr);
      views.push_back({{"name", c.set.views[i].name}, {"brackets", 0}, {"clipped_fraction", 0.0}, {"ghost_fraction", 0.0}});
    }
    r.summary = {{"model", "given radiance (" + c.o.radiance_dir + ")"}, {"recovered_from", "-"},
                 {"curve", nlohmann::json::array()}, {"views", views}};
  });
}

void step_hdr(Context& c) {
  if (!c.o.radiance_dir.empty()) return step_given_radiance(c);
  std::vector<fs::path> inputs;
  for (const PhotoView& v : c.set.views)
    for (const BracketPhoto& b : v.brackets) inputs.push_back(b.file);
  run_step(c, "hdr", {{"response", "auto"}}, inputs, [&](StepRecord& r) {
    fs::create_directories(c.dir / "hdr");
    std::vector<const PhotoView*> all;
    for (const PhotoView& v : c.set.views) all.push_back(&v);
    const PhotoSetResponse psr = recover_photo_set_response(all, RecoveryOptions{}, false);
    const ResponseRecovery& rec = psr.recovery;
    const std::string from = std::to_string(psr.from.size()) + " views (all with brackets)";
    const ResponseCurve& curve = rec.curve;
    nlohmann::json cands = nlohmann::json::array();
    for (const auto& k : rec.candidates)
      cands.push_back({{"model", k.model},
                       {"held_out_error", std::isfinite(k.held_out_error) ? nlohmann::json(k.held_out_error)
                                                                          : nlohmann::json("rejected")}});
    const fs::path response = c.dir / "hdr" / "response.json";
    save_response(response, curve, {{"camera", c.set.camera_name}, {"recovered_from", from}, {"recovery", recovery_json(rec)}});
    nlohmann::json plot = nlohmann::json::array();
    for (int k = 0; k <= 64; ++k) {
      const double z = double(k) * curve.max_code / 64;
      plot.push_back({z, curve.linear(0, z), curve.linear(1, z), curve.linear(2, z)});
    }
    r.outputs.push_back(response);
    nlohmann::json views = nlohmann::json::array();
    Progress bar("hdr", c.o.progress);
    for (std::size_t i = 0; i < c.set.views.size(); ++i) {
      const PhotoView& v = c.set.views[i];
      const ViewMerge vm = merge_photo_view(v, curve, psr.noise, false);
      const BracketSet& b = vm.brackets;
      const NoiseModel& noise = vm.noise;
      const MergedImage& m = vm.image;
      const fs::path exr = c.dir / "hdr" / (v.name + ".exr");
      write_merged_exr(exr.string(), m,
                       {{"version", RSIBR_VERSION}, {"view", v.name}, {"responseModel", curve.model},
                        {"responseFile", "response.json (next to this file)"}, {"colourSpace", working_space()},
                        {"radianceUnit", "X/e: signal over saturation per relative exposure t*iso/100/N^2"},
                        {"producer", "rsibr process (hdr step)"}});
      r.outputs.push_back(exr);
      const double px = double(m.radiance.total());
      views.push_back({{"name", v.name}, {"brackets", b.size()}, {"clipped_fraction", m.clipped / px},
                       {"clipped_pixels", m.clipped},
                       {"ghost_fraction", m.ghost / px}, {"noise_read", noise.read}, {"noise_shot", noise.shot}});
      bar.update(double(i + 1) / double(c.set.views.size()));
    }
    bar.done();
    r.summary = {{"model", curve.model}, {"recovered_from", from}, {"candidates", cands}, {"recovery", recovery_json(rec)},
                 {"curve", plot}, {"max_code", curve.max_code}, {"views", views}};
  });
}

// ---- orient: world_from_cam per view, solved from the chrome ball's reflected features
// (calib/view_orientation.h; world +Y up when `up` gives the world's up in the first camera's
// frame), or given (--poses).
void step_orient(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "camera.cameramodel");
  if (!c.o.poses.empty()) {
    inputs.push_back(c.o.poses);
    const PoseSet given = read_given_poses(c.o.poses);
    for (const PhotoView& v : c.set.views)
      if (!given.find(v.name)) throw std::invalid_argument(c.o.poses + ": no pose for view '" + v.name + "'");
  }
  const nlohmann::json settings = {{"source", c.o.poses.empty() ? "solve" : "given"},
                                   {"up", c.o.up ? nlohmann::json{c.o.up->x(), c.o.up->y(), c.o.up->z()} : nlohmann::json()}};
  run_step(c, "orient", settings, inputs, [&](StepRecord& r) {
    PoseSet poses;
    std::string source;
    nlohmann::json solve;
    if (!c.o.poses.empty()) {
      poses = read_given_poses(c.o.poses);
      source = "given (" + c.o.poses + ")";
    } else {
      const LensModel lens = LensModel::read(c.dir / "camera.cameramodel");
      std::vector<std::string> names;
      std::vector<ViewImage> images;
      for (const PhotoView& v : c.set.views) {
        names.push_back(v.name);
        images.push_back(read_view_image((c.dir / "hdr" / (v.name + ".exr")).string()));
      }
      ViewOrientationOptions vo;
      vo.up = c.o.up;
      ViewOrientationReport report;
      poses = orient_views(names, images, lens, vo, &report);
      source = "solved (chrome-ball features)";
      solve = {{"tracks", report.tracks}, {"observations", report.observations}, {"inliers", report.inliers},
               {"rms_sigmas", report.rms_sigmas}, {"features", report.features},
               {"tracks_relocated", report.track_refinement.tracks_refined}};
    }
    // In the set's order, only its views.
    PoseSet ordered;
    ordered.gauge = poses.gauge;
    for (const PhotoView& v : c.set.views) ordered.views.push_back(*poses.find(v.name));
    const fs::path out = c.dir / "poses.yaml";
    write_pose_file(out.string(), ordered);
    nlohmann::json views = nlohmann::json::array();
    for (const ViewPose& p : ordered.views) {
      const Vec3 forward = p.world_from_cam.col(2);
      views.push_back({{"name", p.name}, {"sigma_deg", p.sigma_deg}, {"forward", {forward.x(), forward.y(), forward.z()}}});
    }
    r.outputs = {out};
    r.summary = {{"source", source}, {"gauge", ordered.gauge}, {"views", views}, {"solve", solve}};
  });
}

// ---- extract: every ball of every view, in the world frame.
int kind_rank(BallKind k) { return k == BallKind::chrome ? 2 : k == BallKind::glossy ? 1 : 0; }

// How mirror-like the ball's image is: a grey (diffuse) ball's image is smooth, its log luminance
// changing by a few stops over the whole disc, while a mirror shows the environment's edges
// (horizon, sun, stand, photographer) compressed toward its rim. The score is the 98th percentile,
// over the pixels within 0.9 radii, of |grad ln(luminance + eps)| in stops per ball radius (central
// differences; eps = 1e-3 of the mean): a grey ball scores a few stops, a chrome ball tens.
double mirror_score(const cv::Mat& rgb, const BallLocation& loc) {
  const double r = loc.radius_px, inner = 0.9 * r;
  std::vector<double> grads;
  cv::Mat lum(rgb.rows, rgb.cols, CV_64F);
  double mean = 0;
  long count = 0;
  for (int py = 0; py < rgb.rows; ++py)
    for (int px = 0; px < rgb.cols; ++px) {
      const cv::Vec3f p = rgb.at<cv::Vec3f>(py, px);
      lum.at<double>(py, px) = std::max(0.0, 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
      if (std::hypot(px - loc.centre_px.x(), py - loc.centre_px.y()) <= inner) mean += lum.at<double>(py, px), ++count;
    }
  if (count < 20 || !(mean > 0)) return 0;
  const double eps = 1e-3 * mean / double(count);
  for (int py = 1; py + 1 < rgb.rows; ++py)
    for (int px = 1; px + 1 < rgb.cols; ++px) {
      if (std::hypot(px - loc.centre_px.x(), py - loc.centre_px.y()) > inner) continue;
      auto l = [&](int x, int y) { return std::log2(lum.at<double>(y, x) + eps); };
      const double gx = 0.5 * (l(px + 1, py) - l(px - 1, py)), gy = 0.5 * (l(px, py + 1) - l(px, py - 1));
      grads.push_back(std::hypot(gx, gy) * r);
    }
  if (grads.empty()) return 0;
  const auto q = grads.begin() + long(0.98 * double(grads.size() - 1));
  std::nth_element(grads.begin(), q, grads.end());
  return *q;
}

void step_extract(Context& c) {
  std::vector<fs::path> inputs = hdr_files(c);
  inputs.push_back(c.dir / "camera.cameramodel");
  inputs.push_back(c.dir / "poses.yaml");
  nlohmann::json balls = nlohmann::json::array();
  for (const BallSpec& b : c.set.balls) balls.push_back({b.name, to_string(b.kind)});
  run_step(c, "extract", {{"map_size", c.o.map_size}, {"balls", balls}}, inputs, [&](StepRecord& r) {
    if (c.set.balls.empty()) throw std::invalid_argument(c.o.photoset + ": balls: the photo set lists no ball");
    const LensModel lens = LensModel::read(c.dir / "camera.cameramodel");
    const PoseSet poses = read_pose_file((c.dir / "poses.yaml").string());
    // World down for the stand mask: -Y when the world is +Y up, else the first camera's +y.
    const Vec3 world_down = poses.gauge == "up" ? Vec3(0, -1, 0) : Vec3(0, 1, 0);
    std::vector<MapSet> sets(c.set.balls.size());
    nlohmann::json views = nlohmann::json::array();
    Progress bar("extract", c.o.progress);
    for (std::size_t vi = 0; vi < c.set.views.size(); ++vi) {
      const PhotoView& v = c.set.views[vi];
      const std::string file = (c.dir / "hdr" / (v.name + ".exr")).string();
      const ViewImage img = read_view_image(file);
      if (img.radiance.cols != lens.width() || img.radiance.rows != lens.height())
        throw std::invalid_argument(file + ": " + std::to_string(img.radiance.cols) + "x" +
                                    std::to_string(img.radiance.rows) + " but the lens model is " +
                                    std::to_string(lens.width()) + "x" + std::to_string(lens.height()));
      const double m = std::min(lens.width(), lens.height());
      std::vector<BallGuess> found = detect_balls(img.radiance, std::max(4.0, m / 40), m / 2, 8);
      if (found.size() < c.set.balls.size())
        throw std::runtime_error(file + ": found " + std::to_string(found.size()) + " ball(s), the photo set lists " +
                                 std::to_string(c.set.balls.size()));
      // The strongest candidates, one per listed ball, located; then matched to the listed balls by
      // appearance: a chrome ball mirrors the whole scene (sharp, high contrast), a grey one is
      // smooth, so ranking by the spread of log luminance inside the disc (mirror_score) and the
      // listed balls by kind (chrome, glossy, grey) pairs them whatever the camera's side of the rig.
      found.resize(c.set.balls.size());
      std::vector<BallLocation> located;
      std::vector<double> score;
      for (const BallGuess& g : found) {
        try {
          located.push_back(locate_ball(img.radiance, lens, g));
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(file + ": " + e.what());
        }
        score.push_back(mirror_score(img.radiance, located.back()));
      }
      std::vector<std::size_t> by_score(found.size()), by_kind(c.set.balls.size());
      for (std::size_t i = 0; i < by_score.size(); ++i) by_score[i] = by_kind[i] = i;
      std::stable_sort(by_score.begin(), by_score.end(), [&](std::size_t p, std::size_t q) { return score[p] > score[q]; });
      std::stable_sort(by_kind.begin(), by_kind.end(), [&](std::size_t p, std::size_t q) {
        return kind_rank(c.set.balls[p].kind) > kind_rank(c.set.balls[q].kind);
      });
      const ViewPose& pose = *poses.find(v.name);
      const Mat3 world_from_cam = pose.world_from_cam;
      nlohmann::json vj = {{"name", v.name}, {"balls", nlohmann::json::array()}};
      for (std::size_t k = 0; k < by_kind.size(); ++k) {
        const std::size_t bi = by_kind[k];
        const BallSpec& ball = c.set.balls[bi];
        const BallLocation& loc = located[by_score[k]];
        ExtractOptions eo;
        eo.size = c.o.map_size;
        eo.mirror = ball.kind == BallKind::chrome;
        eo.indexing = eo.mirror ? SphereIndexing::reflection : SphereIndexing::orthographic;
        eo.camera_mask_deg = eo.mirror ? 12.0 : 0.0;
        eo.down = world_from_cam.transpose() * world_down;
        eo.material = eo.mirror ? "{type: mirror}" : "{type: lambert}";
        // The chrome ball as refined with the orientations (the outline lies inside its limb).
        const BallCone cone = eo.mirror ? extraction_cone(loc, pose, lens) : loc.fit.cone;
        MapView mv = extract_sphere_map(img.radiance, img.flags, lens, cone, world_from_cam, eo);
        mv.attributes["image"] = v.name;
        mv.attributes["ball"] = ball.name;
        mv.attributes["ballKind"] = to_string(ball.kind);
        mv.attributes["frame"] = "world (poses.yaml)";
        const cv::Mat& conf = mv.confidence;
        vj["balls"].push_back({{"ball", ball.name}, {"centre_px", {loc.centre_px.x(), loc.centre_px.y()}},
                               {"radius_px", loc.radius_px}, {"outline_rms_px", loc.fit.rms_px},
                               {"mirror_score", score[by_score[k]]},
                               {"confident_fraction", cv::countNonZero(conf > 0.5) /
                                                          (kPiD / 4 * c.o.map_size * c.o.map_size)}});
        sets[bi].views.push_back(std::move(mv));
      }
      views.push_back(vj);
      bar.update(double(vi + 1) / double(c.set.views.size()));
    }
    bar.done();
    fs::create_directories(c.dir / "maps");
    for (std::size_t bi = 0; bi < c.set.balls.size(); ++bi) {
      const fs::path out = captured_path(c, c.set.balls[bi]);
      write_map_set(out.string(), sets[bi]);
      r.outputs.push_back(out);
    }
    r.summary = {{"views", views}, {"map_size", c.o.map_size}};
  });
}

// ---- probe: the chrome maps blended.
void step_probe(Context& c) {
  const auto chrome = balls_of(c, BallKind::chrome);
  if (chrome.empty()) throw std::invalid_argument(c.o.photoset + ": balls: no chrome ball (the probe needs one)");
  std::vector<fs::path> inputs;
  for (const BallSpec* b : chrome) inputs.push_back(captured_path(c, *b));
  if (!c.o.probe_file.empty()) {
    // The stage swapped for a given environment (the truth, for the error budget): resampled
    // (area-weighted, core/resample.h) to the probe's lat-long size.
    run_step(c, "probe", {{"width", c.o.probe_width}, {"given", c.o.probe_file}}, {c.o.probe_file}, [&](StepRecord& r) {
      EnvMap env = resample(read_environment(c.o.probe_file), Layout(LayoutKind::LatLong, c.o.probe_width, c.o.probe_width / 2));
      env.attributes["producer"] = "rsibr process (given probe " + fs::path(c.o.probe_file).filename().string() + ")";
      const fs::path out = c.dir / "probe.exr";
      write_environment(out.string(), env);
      r.outputs = {out};
      r.summary = {{"views", 0}, {"width", c.o.probe_width}, {"covered_fraction", 1.0}, {"fresnel", "given: " + c.o.probe_file}};
    });
    return;
  }
  run_step(c, "probe", {{"width", c.o.probe_width}, {"fresnel", c.o.chrome_fresnel}}, inputs, [&](StepRecord& r) {
    MapSet all;
    for (const fs::path& p : inputs)
      for (MapView& v : read_map_set(p.string()).views) all.views.push_back(std::move(v));
    ProbeOptions po;
    po.width = c.o.probe_width;
    std::shared_ptr<const Fresnel> fresnel;
    if (!c.o.chrome_fresnel.empty()) fresnel = make_fresnel(YAML::Load(c.o.chrome_fresnel), "--chrome-fresnel");
    po.fresnel = fresnel.get();
    Probe p = assemble_probe(all, po);
    p.env.attributes["views"] = std::to_string(all.views.size());
    p.env.attributes["producer"] = "rsibr process (probe step)";
    p.env.attributes["version"] = RSIBR_VERSION;
    const fs::path out = c.dir / "probe.exr";
    write_environment(out.string(), p.env);
    r.outputs = {out};
    r.summary = {{"views", all.views.size()}, {"width", c.o.probe_width}, {"covered_fraction", p.covered_fraction},
                 {"fresnel", fresnel ? fresnel->spec() : "none (the probe holds F L)"}};
  });
}

// ---- bake: computed maps of the grey balls from the probe, at the captured views.
void step_bake(Context& c) {
  std::vector<fs::path> inputs = {c.dir / "probe.exr"};
  const auto greys = balls_of(c, BallKind::grey);
  for (const BallSpec* b : greys) inputs.push_back(captured_path(c, *b));
  const nlohmann::json settings = {{"albedo", c.o.grey_albedo}, {"method", c.o.bake_method},
                                   {"samples", c.o.bake_samples}, {"seed", c.o.seed}};
  run_step(c, "bake", settings, inputs, [&](StepRecord& r) {
    const EnvMap probe = read_environment((c.dir / "probe.exr").string());
    const auto integrator = make_integrator(c.o.bake_method, probe);
    std::ostringstream spec;
    spec << std::setprecision(9) << "{type: lambert, albedo: [" << c.o.grey_albedo << ", " << c.o.grey_albedo << ", "
         << c.o.grey_albedo << "]}";
    const auto brdf = parse_brdf(spec.str());
    IntegratorOptions io;
    io.samples = c.o.bake_samples;
    io.seed = c.o.seed;
    nlohmann::json balls = nlohmann::json::array();
    for (const BallSpec* b : greys) {
      const MapSet captured = read_map_set(captured_path(c, *b).string());
      MapSet computed;
      for (const MapView& cv : captured.views) {
        MapView mv;
        mv.view = cv.view;
        mv.world_from_view = cv.world_from_view;
        mv.warp = "normal";
        mv.source = "computed";
        mv.material = brdf->spec();
        mv.attributes = {{"version", RSIBR_VERSION}, {"environment", "probe.exr"}, {"method", c.o.bake_method},
                         {"samples", std::to_string(c.o.bake_samples)}, {"seed", std::to_string(c.o.seed)},
                         {"image", cv.attributes.count("image") ? cv.attributes.at("image") : ""}};
        mv.rgb = integrator->radiance_map(*brdf, mv.view, mv.world_from_view, cv.rgb.cols, io);
        computed.views.push_back(std::move(mv));
      }
      const fs::path out = computed_path(c, *b);
      write_map_set(out.string(), computed);
      r.outputs.push_back(out);
      balls.push_back({{"ball", b->name}, {"views", computed.views.size()}});
    }
    r.summary = {{"material", brdf->spec()}, {"balls", balls}, {"method", c.o.bake_method}};
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
      const MapSet captured = read_map_set(captured_path(c, *b).string());
      const MapSet computed = read_map_set(computed_path(c, *b).string());
      CompareOptions co;
      co.name_a = captured_path(c, *b).string();
      co.name_b = computed_path(c, *b).string();
      const Comparison cmp = compare_map_sets(captured, computed, co);
      std::vector<cv::Mat> errors, weights;
      for (const PairComparison& p : cmp.pairs) {
        errors.push_back(log_error_image(p.images.a, p.images.b, p.images.weight, cmp.settings.log_epsilon,
                                         cmp.fit ? cmp.fit->gains : std::array<double, 3>{1, 1, 1}));
        weights.push_back(p.images.weight);
      }
      const double heat_max = heat_scale_max(errors, weights);
      const float exposure = auto_exposure(cmp.before.mean_b[0], cmp.before.mean_b[1], cmp.before.mean_b[2]);
      FolderContents files;
      nlohmann::json views = nlohmann::json::array();
      for (std::size_t i = 0; i < cmp.pairs.size(); ++i) {
        const PairComparison& p = cmp.pairs[i];
        SideBySideInput in;
        in.a_rgb = cmp.fit ? apply_gains(p.images.a, cmp.fit->gains) : p.images.a;
        in.b_rgb = p.images.b;
        in.error = errors[i];
        in.weight = p.images.weight;
        in.exposure_stops = exposure;
        in.heat_max = heat_max;
        const std::string image = captured.views[p.index_a].attributes.count("image")
                                      ? captured.views[p.index_a].attributes.at("image") : p.name;
        in.title = b->name + " " + image;
        in.a_label = "captured x gains";
        in.b_label = "computed";
        in.heat_label = "log2 error";
        const std::string name = p.name + ".png";
        files[name] = png_bytes(side_by_side(in), name);
        views.push_back({{"name", p.name}, {"image", image}, {"picture", name},
                         {"view", {p.view.x(), p.view.y(), p.view.z()}},
                         {"before", metrics_json(p.before)}, {"after", metrics_json(p.after)}});
      }
      const fs::path folder = c.dir / "compare" / b->name;
      fs::create_directories(folder.parent_path());
      write_folder_atomically(folder, files);
      for (const auto& [name, bytes] : files) r.outputs.push_back(folder / name);
      nlohmann::json bj = {{"ball", b->name}, {"folder", folder.string()}, {"views", views},
                           {"overall", {{"before", metrics_json(cmp.before)}, {"after", metrics_json(cmp.after)}}},
                           {"heat_max_stops", heat_max}, {"log_epsilon", cmp.settings.log_epsilon}};
      if (cmp.fit)
        bj["fit"] = {{"gains", cmp.fit->gains}, {"exposure_stops", cmp.fit->exposure_stops}, {"chroma", cmp.fit->chroma}};
      balls.push_back(bj);
    }
    r.summary = {{"balls", balls}};
  });
}

// ---- render: a turntable of a mesh lit by the probe, through the runtime.
void step_render(Context& c) {
  std::vector<fs::path> inputs = {c.dir / "probe.exr"};
  if (!c.o.mesh.empty()) inputs.push_back(c.o.mesh);
  const nlohmann::json settings = {{"brdf", c.o.render_brdf}, {"res", c.o.render_views_res}, {"frames", c.o.turntable},
                                   {"size", {c.o.render_width, c.o.render_height}}, {"seed", c.o.seed},
                                   {"mesh", c.o.mesh.empty() ? "built-in torus" : c.o.mesh}};
  run_step(c, "render", settings, inputs, [&](StepRecord& r) {
    const EnvMap probe = read_environment((c.dir / "probe.exr").string());
    const auto brdf = parse_brdf(c.o.render_brdf);
    const auto integrator = make_integrator("fis", probe);
    IntegratorOptions io;
    io.samples = 32;
    io.seed = c.o.seed;
    MapSet maps;
    const ViewSet views = ViewSet::named("icosa");
    const std::string warp = brdf->central_direction() == Lobe::Normal ? "normal" : "mirror";
    for (const Vec3& v : views.views()) {
      MapView mv;
      mv.view = v;
      mv.world_from_view = world_from_view_for(v);
      mv.warp = warp;
      mv.source = "computed";
      mv.material = brdf->spec();
      mv.attributes = {{"version", RSIBR_VERSION}, {"environment", "probe.exr"}, {"method", "fis"},
                       {"samples", "32"}, {"seed", std::to_string(c.o.seed)}};
      mv.rgb = integrator->radiance_map(*brdf, v, mv.world_from_view, c.o.render_views_res, io);
      maps.views.push_back(std::move(mv));
    }
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
    // Display exposure: the probe's mean at mid-grey.
    const cv::Scalar mean = cv::mean(probe.pixels);
    const float stops = auto_exposure(mean[0], mean[1], mean[2]);
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
    r.summary = {{"mesh", c.o.mesh.empty() ? "built-in torus" : c.o.mesh}, {"triangles", mesh.triangles.size()},
                 {"material", brdf->spec()}, {"frames", c.o.turntable}, {"seconds_per_frame", seconds / c.o.turntable},
                 {"display_exposure_stops", stops}};
  });
}

}  // namespace

const std::vector<std::string>& process_steps() {
  static const std::vector<std::string> steps = {"calibrate", "hdr",  "orient", "extract", "probe",
                                                 "bake",      "compare", "render", "report"};
  return steps;
}

ProcessResult run_process(const ProcessOptions& o) {
  for (const std::string& f : o.force)
    if (f != "all" && std::find(process_steps().begin(), process_steps().end(), f) == process_steps().end())
      throw std::invalid_argument("--force '" + f + "': not a step (calibrate, hdr, orient, extract, probe, bake, "
                                  "compare, render, report, all)");
  if (!o.lens.empty() && !fs::is_regular_file(o.lens)) throw std::invalid_argument(o.lens + ": no such file");
  if (!o.mesh.empty() && !fs::is_regular_file(o.mesh)) throw std::invalid_argument(o.mesh + ": no such file");
  if (!o.probe_file.empty() && !fs::is_regular_file(o.probe_file)) throw std::invalid_argument(o.probe_file + ": no such file");
  if (!o.radiance_dir.empty() && !fs::is_directory(o.radiance_dir))
    throw std::invalid_argument(o.radiance_dir + ": no such folder");
  if (!o.poses.empty()) read_given_poses(o.poses);  // errors before any work
  if (o.up && !(o.up->norm() > 0 && o.up->allFinite())) throw std::invalid_argument("--up: expected a non-zero direction");
  parse_brdf(o.render_brdf);
  if (!o.chrome_fresnel.empty()) {
    try {
      make_fresnel(YAML::Load(o.chrome_fresnel), "--chrome-fresnel");
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--chrome-fresnel: ") + e.what());
    }
  }
  ProcessResult result;
  Context c{o, fs::absolute(o.out).lexically_normal(), load_photo_set(o.photoset), result};
  if (c.set.views.empty()) throw std::invalid_argument(o.photoset + ": views: none");
  if (fs::exists(c.dir) && !fs::is_directory(c.dir)) throw std::invalid_argument(o.out.string() + ": not a folder");
  if (!fs::is_directory(c.dir.parent_path()))
    throw std::invalid_argument(o.out.string() + ": its parent folder does not exist");
  // No output may land on an input (the photo folder itself must not be DIR).
  if (fs::exists(c.dir) && fs::equivalent(c.dir, c.set.folder))
    throw std::invalid_argument(o.out.string() + ": is the photo set's folder; choose another output folder");
  fs::create_directories(c.dir);

  step_calibrate(c);
  step_hdr(c);
  step_orient(c);
  step_extract(c);
  step_probe(c);
  step_bake(c);
  step_compare(c);
  step_render(c);

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
