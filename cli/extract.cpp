// rsibr extract: one view's linear image (a merged view of `rsibr hdr`, or any float RGB EXR) + the
// lens model -> the ball located (calib/balls/ball_locator.h) -> its sphere map with a confidence channel
// (calib/extraction/sphere_map_extraction.h), written as a captured one-view map set. With --photoset, the
// rig mode of rsibr process's extract step (pipeline/extract_step.h): every listed ball of every
// posed view, identified across views, one map set per ball.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "calib/balls/ball_identification.h"
#include "calib/balls/ball_locator.h"
#include "calib/balls/balls_file.h"
#include "calib/orientation/pose_file.h"
#include "calib/orientation/view_orientation.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "calib/view_image.h"
#include "formats/atomic_file.h"
#include "core/lens_model.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "core/progress.h"
#include "calib/lens/far_camera.h"
#include "formats/atomic_folder.h"
#include "formats/photo_set.h"
#include "calib/probe/probe.h"
#include "pipeline/ball_override.h"
#include "pipeline/extract_step.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

namespace rsibr::cli {
namespace {

struct ExtractArgs {
  std::string image, lens, out, ball, kind = "chrome", indexing = "reflection", json, poses;
  int which = 0, size = 128;
  double camera_mask_deg = -1, stand_mask_deg = 8;
  bool quiet = false, no_stand = false;
  // The rig mode (--photoset).
  std::string photoset, merged, chrome_fresnel = kDefaultChromeFresnel;
  std::vector<std::string> balls;  // --view-ball VIEW:BALL=X,Y,R
  std::string balls_file;          // --balls: rsibr process's DIR/balls.json
  bool size_given = false, no_occluder_light = false, no_recover = false;
  int probe_width = 0;
  double grey_albedo = 0.18;
  std::uint64_t seed = 0;
};

// Every listed ball of every posed view (pipeline/extract_step.h, as rsibr process runs it):
// OUT/captured-<ball>.exr per ball and OUT/masks/, written only when every ball was extracted.
int run_extract_rig(const ExtractArgs& a) {
  if (a.poses.empty()) throw std::invalid_argument("--photoset: needs --poses (rsibr orient's poses.yaml)");
  if (!a.image.empty()) throw std::invalid_argument("--photoset: give the merged views with --merged, not an image");
  if (a.merged.empty()) throw std::invalid_argument("--photoset: needs --merged (the folder rsibr hdr wrote)");
  const PhotoSet set = load_photo_set(a.photoset);
  if (set.balls.empty()) throw std::invalid_argument(a.photoset + ": balls: the photo set lists no ball");
  const LensModel lens = LensModel::read(a.lens);
  ExtractStep s;
  s.lens = &lens;
  s.poses = read_pose_file(a.poses);
  std::vector<BallOverride> overrides;
  try {
    overrides = parse_ball_overrides(a.balls, set);
  } catch (const std::invalid_argument& e) {
    // The library names the option as rsibr process spells it.
    const std::string what = e.what();
    throw std::invalid_argument(what.rfind("--ball ", 0) == 0 ? "--view-ball " + what.substr(7) : what);
  }
  if (!a.balls_file.empty() && !overrides.empty())
    throw std::invalid_argument("--view-ball: not with --balls (the file's balls are used)");
  std::vector<std::filesystem::path> inputs = {a.lens, a.poses};
  // The balls of the posed views: from the file, else found here as the balls step finds them.
  ShootBallsInput found;
  found.lens = lens;
  found.listed = listed_balls(set);
  for (const PhotoView& v : set.views) {
    s.views.push_back(v.name);
    const std::filesystem::path file = std::filesystem::path(a.merged) / (v.name + ".exr");
    if (s.poses.find(v.name)) {
      if (!std::filesystem::is_regular_file(file))
        throw std::invalid_argument(file.string() + ": missing (the merged view of posed view '" + v.name + "')");
      inputs.push_back(file);
      found.views.push_back(v.name);
      found.given.emplace_back();
      for (const ListedBall& b : found.listed) found.given.back().push_back(find_override(overrides, v.name, b.name));
    }
  }
  if (!a.balls_file.empty()) {
    inputs.push_back(a.balls_file);
    s.found = read_balls_file(a.balls_file);
    check_listed_balls(s.found, found.listed, a.balls_file);
  }
  // A view of the lens's size as it is; crops of the ball on a far camera's canvas (calib/lens/far_camera.h).
  // Any other lens of another size is the wrong lens: refused, as rsibr process refuses it.
  const bool far = is_far_camera(lens);
  s.read_view = [&](const std::string& name) {
    const std::string file = (std::filesystem::path(a.merged) / (name + ".exr")).string();
    ViewImage img = read_view_image(file);
    if (!far && (img.radiance.cols != lens.width() || img.radiance.rows != lens.height()))
      throw std::invalid_argument(file + ": " + std::to_string(img.radiance.cols) + "x" +
                                  std::to_string(img.radiance.rows) + " but the lens model " + a.lens + " is " +
                                  std::to_string(lens.width()) + "x" + std::to_string(lens.height()));
    return on_lens_canvas(std::move(img), lens, file);
  };
  if (a.balls_file.empty()) {
    found.read_view = [&](std::size_t v) {
      return read_view_image((std::filesystem::path(a.merged) / (found.views[v] + ".exr")).string());
    };
    s.found = find_shoot_balls(found);
  }
  s.map_size = a.size_given ? a.size : 0;
  s.probe_width = a.probe_width;
  s.occluder_light = !a.no_occluder_light;
  s.chrome_fresnel = a.chrome_fresnel;
  s.recover_sources = !a.no_recover;
  s.grey_albedo = a.grey_albedo;
  s.seed = a.seed;
  s.progress = !a.quiet && Progress::stderr_is_terminal();

  OutputPlan outputs(inputs);
  outputs.folder(a.out);
  const std::string json = outputs.file(a.json);
  ExtractedMaps e = run_extract_step(s);
  // The map sets pass through a temporary file each (the EXR writer writes files), then every
  // output goes into OUT at once.
  FolderContents files;
  const std::filesystem::path tmp =
      std::filesystem::temp_directory_path() / ("rsibr-extract-" + std::to_string(::getpid()) + ".exr");
  for (std::size_t b = 0; b < set.balls.size(); ++b) {
    try {
      write_map_set(tmp.string(), e.sets[b]);
      std::ifstream in(tmp, std::ios::binary);
      files["captured-" + set.balls[b].name + ".exr"] =
          std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    } catch (...) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw;
    }
    std::filesystem::remove(tmp);
  }
  for (const auto& [name, bytes] : e.masks) files["mask-" + name] = bytes;
  for (auto& view : e.summary["views"])
    for (auto& ball : view["balls"])
      if (ball.contains("mask"))
        ball["mask"] = "mask-" + ball["mask"].get<std::string>().substr(std::string("masks/").size());
  e.summary["out"] = a.out;
  write_summary(json, e.summary);
  write_folder_atomically(a.out, files);
  outputs.commit();
  if (!a.quiet && a.json != "-")
    for (std::size_t b = 0; b < set.balls.size(); ++b)
      std::cerr << "rsibr extract: " << set.balls[b].name << ": " << e.sets[b].views.size() << " of "
                << set.views.size() << " views -> " << a.out << "/captured-" << set.balls[b].name << ".exr\n";
  return 0;
}

BallGuess parse_ball(const std::string& text) {
  BallGuess g;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  double x = 0, y = 0, r = 0;
  if (!(in >> x >> c1 >> y >> c2 >> r) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !std::isfinite(x) ||
      !std::isfinite(y) || !(r > 1) || !std::isfinite(r))
    throw std::invalid_argument("--ball '" + text + "': expected X,Y,R in pixels with R > 1");
  g.centre_px = Vec2(x, y);
  g.radius_px = r;
  return g;
}

int run_extract(const ExtractArgs& a) {
  if (!a.photoset.empty()) return run_extract_rig(a);
  if (a.image.empty()) throw std::invalid_argument("extract: give an IMAGE, or --photoset for every view and ball");
  OutputPlan outputs({a.image, a.lens, a.poses});
  const std::string exr = outputs.file(a.out), json = outputs.file(a.json);
  if (a.kind != "chrome" && a.kind != "grey")
    throw std::invalid_argument("--kind '" + a.kind + "': expected chrome or grey");
  if (a.indexing != "reflection" && a.indexing != "orthographic")
    throw std::invalid_argument("--indexing '" + a.indexing + "': expected reflection or orthographic");
  std::optional<BallGuess> given;
  if (!a.ball.empty()) given = parse_ball(a.ball);

  std::optional<PoseSet> poses;
  if (!a.poses.empty()) poses = read_pose_file(a.poses);
  const LensModel lens = LensModel::read(a.lens);
  ViewImage view = read_view_image(a.image);
  // --poses: the world frame of the pose file's entry named like the image (header rsibr.view, else the stem).
  std::string pose_name;
  if (poses) {
    pose_name = view.name.empty() ? std::filesystem::path(a.image).stem().string() : view.name;
    const ViewPose* p = poses->find(pose_name);
    if (!p) throw std::invalid_argument(a.poses + ": no view named '" + pose_name + "' (the view of " + a.image + ")");
    view.world_from_cam = p->world_from_cam;
  }
  if (view.radiance.cols != lens.width() || view.radiance.rows != lens.height())
    throw std::invalid_argument(a.image + ": " + std::to_string(view.radiance.cols) + "x" +
                                std::to_string(view.radiance.rows) + " but the lens model " + a.lens + " is " +
                                std::to_string(lens.width()) + "x" + std::to_string(lens.height()));

  // The ball: given, or among the candidates with a clean outline (calib/balls/ball_identification.h),
  // left to right.
  int candidates = 0;
  BallLocation loc;
  if (given) {
    // A ball must overlap the image and be no larger than it (the outline search scales with R).
    const double w = view.radiance.cols, h = view.radiance.rows;
    if (given->radius_px > std::hypot(w, h) || given->centre_px.x() < -given->radius_px ||
        given->centre_px.y() < -given->radius_px || given->centre_px.x() > w + given->radius_px ||
        given->centre_px.y() > h + given->radius_px)
      throw std::invalid_argument("--ball '" + a.ball + "': the ball does not fit the " + std::to_string(int(w)) + "x" +
                                  std::to_string(int(h)) + " image");
    try {
      loc = locate_ball(view.radiance, lens, *given);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(a.image + ": " + e.what());
    }
  } else {
    std::vector<BallCandidate> found = find_ball_candidates(view.radiance, lens);
    candidates = static_cast<int>(found.size());
    if (a.which >= candidates)
      throw std::invalid_argument(a.image + ": found " + std::to_string(candidates) + " ball(s), --which " +
                                  std::to_string(a.which) + " asked for; give the ball with --ball X,Y,R");
    std::sort(found.begin(), found.end(),
              [](const BallCandidate& p, const BallCandidate& q) { return p.loc.centre_px.x() < q.loc.centre_px.x(); });
    loc = found[std::size_t(a.which)].loc;
  }

  ExtractOptions o;
  o.size = a.size;
  o.indexing = a.indexing == "reflection" ? SphereIndexing::reflection : SphereIndexing::orthographic;
  o.mirror = a.kind == "chrome";
  o.camera_mask_deg = a.camera_mask_deg >= 0 ? a.camera_mask_deg : (o.mirror ? 12.0 : 0.0);
  const Mat3 world_from_cam = view.world_from_cam.value_or(Mat3::Identity());
  if (!a.no_stand) {
    o.down = world_from_cam.transpose() * Vec3(0, -1, 0);  // world down (camera frame); the camera's when no pose
    o.stand_mask_deg = a.stand_mask_deg;
  }
  o.material = o.mirror ? "{type: mirror}" : "{type: lambert}";
  // A chrome ball with --poses: the pose file's ball refined with the orientations (rsibr orient),
  // when it is this ball; the outline lies inside a mirror ball's limb.
  const ViewPose* pose = poses ? poses->find(pose_name) : nullptr;
  bool ball_from_pose = false;
  if (pose && o.mirror) {
    const BallCone cone = extraction_cone(loc, *pose, lens);
    ball_from_pose = pose->ball && cone.axis == pose->ball->axis;
    loc.fit.cone = cone;
    loc.centre_px = lens.project(cone.axis);
  }
  MapView mv = extract_sphere_map(view.radiance, view.flags, lens, loc.fit.cone, world_from_cam, o);
  std::ostringstream centre;
  centre.precision(10);
  centre << loc.centre_px.x() << " " << loc.centre_px.y();
  mv.image = std::filesystem::path(a.image).filename().string();
  mv.attributes["lens"] = std::filesystem::path(a.lens).filename().string();
  mv.attributes["ballCentrePx"] = centre.str();
  mv.attributes["ballHalfAngleRad"] = std::to_string(loc.fit.cone.half_angle);
  mv.attributes["ballKind"] = a.kind;
  mv.attributes["frame"] =
      poses ? "world (pose file " + std::filesystem::path(a.poses).filename().string() + ", view " + pose_name + ")"
      : view.world_from_cam ? "world (image header pose)"
                            : "camera (no pose)";
  MapSet set;
  set.views.push_back(std::move(mv));
  write_map_set(exr, set);

  const cv::Mat& conf = set.views.front().confidence;
  nlohmann::json j;
  j["image"] = a.image;
  j["lens"] = a.lens;
  j["out"] = a.out;
  j["kind"] = a.kind;
  j["indexing"] = a.indexing;
  j["size"] = a.size;
  j["detected_candidates"] = candidates;
  j["ball"] = {{"centre_px", {loc.centre_px.x(), loc.centre_px.y()}},
               {"radius_px", loc.radius_px},
               {"axis_cam", {loc.fit.cone.axis.x(), loc.fit.cone.axis.y(), loc.fit.cone.axis.z()}},
               {"half_angle_deg", loc.fit.cone.half_angle * 180 / kPi},
               {"distance_in_radii", 1 / std::sin(loc.fit.cone.half_angle)},
               {"outline_points", loc.outline_px.size()},
               {"inliers", loc.fit.inliers},
               {"rms_px", loc.fit.rms_px}};
  j["pose_from_header"] = view.world_from_cam.has_value() && !poses;
  j["pose_from_file"] = poses ? nlohmann::json(pose_name) : nlohmann::json(nullptr);
  j["ball_from_pose"] = ball_from_pose;
  j["mean_confidence_in_disc"] = cv::mean(conf, conf > 0)[0];
  j["confident_fraction"] = cv::countNonZero(conf > 0.5) / (kPi / 4 * a.size * a.size);
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-")
    std::cerr << "ball at (" << loc.centre_px.x() << ", " << loc.centre_px.y() << "), radius " << loc.radius_px
              << " px, outline RMS " << loc.fit.rms_px << " px -> " << a.out << "\n";
  return 0;
}

}  // namespace

Runner add_extract(CLI::App& app) {
  auto a = std::make_shared<ExtractArgs>();
  CLI::App* c = app.add_subcommand("extract",
                                   "Locate a ball in a view's HDR image and extract its sphere map (captured map set)");
  c->footer(
      "The ball is found by a Hough transform (or --ball X,Y,R), located to sub-pixel accuracy by a cone fit to its "
      "outline through the lens model, and its sphere map is extracted in the view frame (z from the ball toward the "
      "camera): each texel from the surface point that reflects its mirror direction (--indexing reflection, exact "
      "for chrome) or whose normal is the texel's (orthographic, exact for grey). The confidence channel is 0 outside "
      "the ball, on clipped pixels, at the camera's reflection and the stand, and fades at the stretched rim. "
      "The map's world frame is the pose file's (--poses, from rsibr orient; the entry named like the image: its "
      "header's rsibr.view, else the file stem), else the image header's rsibr.worldFromCam, else the camera's.\n"
      "Example: rsibr extract hdr/north.exr --lens camera.cameramodel --out north-chrome.exr --json -");
  c->add_option("image", a->image, "Merged view EXR (rsibr hdr) or float RGB EXR (not with --photoset)");
  c->add_option("--lens", a->lens, "mrcal .cameramodel of the camera")->required();
  c->add_option("--out", a->out, "Output map set (.exr)")->required();
  c->add_option("--ball", a->ball, "Ball guess X,Y,R in pixels (default: detected)");
  c->add_option("--which", a->which, "Detected ball to use, 0 = leftmost")->check(CLI::Range(0, 7));
  c->add_option("--kind", a->kind, "chrome (mirror map) or grey (normal map)");
  c->add_option("--indexing", a->indexing, "reflection (exact for mirrors) or orthographic");
  c->add_option("--size", a->size, "Map size in texels (square; --photoset: default from the balls' pixel radii)")
      ->check(CLI::Range(8, 4096))
      ->each([a](const std::string&) { a->size_given = true; });
  c->add_option("--camera-mask-deg", a->camera_mask_deg,
                "Mask reflections within this of the camera (default 12 chrome, 0 grey)")
      ->check(CLI::Range(0.0, 90.0));
  c->add_option("--stand-mask-deg", a->stand_mask_deg, "Mask directions within this of straight down")
      ->check(CLI::Range(0.0, 90.0));
  c->add_flag("--no-stand", a->no_stand, "No stand mask");
  c->add_option("--poses", a->poses,
                "Pose file (rsibr orient): the world frame of the entry named like the image, and for a chrome ball "
                "its cone as refined with the orientations");
  c->add_option("--photoset", a->photoset,
                "Rig mode: every ball the photo set lists in every posed view, identified across views, as rsibr "
                "process's extract step; --out is then a folder (captured-<ball>.exr, mask-<view>[-<ball>].png)");
  c->add_option("--merged", a->merged, "Rig mode: the folder of merged views <view>.exr (rsibr hdr --out)");
  c->add_option("--view-ball", a->balls, "Rig mode: VIEW:BALL=X,Y,R gives one ball of one view by hand (repeatable)");
  c->add_option("--balls", a->balls_file,
                "Rig mode: the balls as rsibr process's balls step found them (DIR/balls.json); default: found here");
  c->add_option("--chrome-fresnel", a->chrome_fresnel,
                "Rig mode: the chrome ball's Fresnel spec, for the grey balls' occluded light");
  c->add_option("--grey-albedo", a->grey_albedo, "Rig mode: the grey ball's albedo")->check(CLI::Range(0.001, 1.0));
  c->add_option("--probe-width", a->probe_width, "Rig mode: width of the probe the occluded light is read from")
      ->check(CLI::Range(16, 1 << 14));
  c->add_flag("--no-occluder-light", a->no_occluder_light,
              "Rig mode: do not restore the light the photographer takes from the grey balls");
  c->add_flag("--no-recover", a->no_recover, "Rig mode: that probe without the clipped light recovered");
  c->add_option("--seed", a->seed, "Rig mode: seed of the light recovery");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No report line");
  return [a] { return run_extract(*a); };
}

}  // namespace rsibr::cli
