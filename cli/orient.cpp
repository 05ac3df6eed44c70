// rsibr orient: merged views (rsibr hdr) + the lens model -> every view's orientation from the
// features in its chrome ball (calib/orientation/view_orientation.h), written as a pose file (calib/orientation/pose_file.h).
#include "cli/summary.h"
#include "cli/verbs.h"

#include "calib/orientation/point_pairs.h"
#include "calib/orientation/pose_file.h"
#include "calib/orientation/view_orientation.h"
#include "formats/atomic_file.h"
#include "core/lens_model.h"
#include "formats/output_plan.h"
#include "core/progress.h"
#include "core/safe_name.h"
#include "pipeline/orientation_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>

namespace rsibr::cli {
namespace {

struct OrientArgs {
  std::vector<std::string> images;
  std::string lens, out, up, json, points;
  std::vector<std::string> balls;  // VIEW=X,Y,R
  bool quiet = false;
};

// "VIEW=X,Y,R": the chrome ball of that view, roughly (within ~20%).
std::pair<std::string, BallGuess> parse_chrome_ball(const std::string& text) {
  const auto eq = text.find('=');
  std::istringstream in(eq == std::string::npos ? std::string() : text.substr(eq + 1));
  double x = 0, y = 0, r = 0;
  char c1 = 0, c2 = 0;
  if (eq == std::string::npos || eq == 0 || !(in >> x >> c1 >> y >> c2 >> r) || c1 != ',' || c2 != ',' ||
      !(in >> std::ws).eof() || !std::isfinite(x) || !std::isfinite(y) || !(r > 1 && std::isfinite(r)))
    throw std::invalid_argument("--ball '" + text +
                                "': expected VIEW=X,Y,R (the chrome ball's centre and radius, pixels)");
  return {text.substr(0, eq), BallGuess{Vec2(x, y), r}};
}

Vec3 parse_up(const std::string& text) {
  std::istringstream in(text);
  double x = 0, y = 0, z = 0;
  char c1 = 0, c2 = 0;
  if (!(in >> x >> c1 >> y >> c2 >> z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !std::isfinite(x) ||
      !std::isfinite(y) || !std::isfinite(z) || Vec3(x, y, z).norm() < 1e-12)
    throw std::invalid_argument("--up '" + text +
                                "': expected X,Y,Z, a non-zero direction in the first camera's frame");
  return Vec3(x, y, z);
}

int run_orient(const OrientArgs& a) {
  std::vector<std::filesystem::path> inputs(a.images.begin(), a.images.end());
  inputs.push_back(a.lens);
  OutputPlan outputs(inputs);
  const std::string pose_file = outputs.file(a.out), json = outputs.file(a.json);
  ViewOrientationOptions o;
  if (a.up == "auto")
    o.estimate_up = true;
  else if (!a.up.empty())
    o.up = parse_up(a.up);
  if (a.images.size() < 2)
    throw std::invalid_argument("orient: " + std::to_string(a.images.size()) + " image(s), need at least 2 views");
  const LensModel lens = LensModel::read(a.lens);
  std::vector<std::string> names;
  std::vector<ViewImage> views;
  std::set<std::string> seen;
  {
    Progress bar("orient", !a.quiet && Progress::stderr_is_terminal());
    for (std::size_t i = 0; i < a.images.size(); ++i) {
      views.push_back(read_view_image(a.images[i]));
      const std::string name =
          views.back().name.empty() ? std::filesystem::path(a.images[i]).stem().string() : views.back().name;
      require_safe_name(name, a.images[i] + ": the view name (from the header's rsibr.view, else the file name)");
      if (!seen.insert(name).second)
        throw std::invalid_argument(a.images[i] + ": view name '" + name + "' is already taken by another image");
      names.push_back(name);
      bar.update(double(i + 1) / a.images.size());
    }
  }
  if (!a.points.empty()) o.points = read_point_pairs(a.points);
  if (!a.balls.empty()) {
    o.given_chrome.assign(names.size(), std::nullopt);
    for (const std::string& text : a.balls) {
      const auto [view, guess] = parse_chrome_ball(text);
      const auto it = std::find(names.begin(), names.end(), view);
      if (it == names.end())
        throw std::invalid_argument("--ball '" + text + "': no view '" + view + "' among the images");
      if (o.given_chrome[std::size_t(it - names.begin())])
        throw std::invalid_argument("--ball '" + text + "': view '" + view + "' is given twice");
      o.given_chrome[std::size_t(it - names.begin())] = guess;
    }
  }
  ViewOrientationReport rep;
  PoseSet poses;
  try {
    poses = orient_views(names, views, lens, o, &rep);
  } catch (const std::exception& e) {
    // What was found before it stopped, when a summary was asked for (no pose file is written).
    if (!a.json.empty()) {
      nlohmann::json f = {{"images", a.images},
                          {"lens", a.lens},
                          {"error", e.what()},
                          {"left_out", rep.left_out},
                          {"notes", rep.notes},
                          {"features", rep.features},
                          {"pairs", pair_orientation_json(rep.pairs)}};
      write_summary(a.json, f);
    }
    if (!dynamic_cast<const std::invalid_argument*>(&e)) throw;
    // "<name>: ..." -> the image's path, so the line names the file.
    const std::string what = e.what();
    for (std::size_t i = 0; i < names.size(); ++i)
      if (what.rfind(names[i] + ": ", 0) == 0) throw std::invalid_argument(a.images[i] + what.substr(names[i].size()));
    throw;
  }
  write_pose_file(pose_file, poses);

  nlohmann::json j;
  j["images"] = a.images;
  j["lens"] = a.lens;
  j["out"] = a.out;
  j["gauge"] = poses.gauge;
  j["tracks"] = rep.tracks;
  j["observations"] = rep.observations;
  j["inliers"] = rep.inliers;
  j["rms_sigmas"] = rep.rms_sigmas;
  j["pairs"] = pair_orientation_json(rep.pairs);
  j["tracks_relocated"] = {{"tracks", rep.track_refinement.tracks_refined},
                           {"observations", rep.track_refinement.observations_refined},
                           {"dropped", rep.track_refinement.observations_dropped},
                           {"median_sigma_ratio", rep.track_refinement.median_sigma_ratio}};
  nlohmann::json jv = nlohmann::json::array();
  for (std::size_t v = 0; v < poses.views.size(); ++v) {
    const BallLocation& b = rep.balls[v];
    std::vector<double> m;
    for (int k = 0; k < 9; ++k) m.push_back(poses.views[v].world_from_cam(k / 3, k % 3));
    const std::size_t image = std::size_t(std::find(names.begin(), names.end(), poses.views[v].name) - names.begin());
    jv.push_back(
        {{"name", poses.views[v].name},
         {"image", a.images[image]},
         {"world_from_cam", m},
         {"sigma_deg", poses.views[v].sigma_deg},
         {"features", rep.features[v]},
         {"ball",
          {{"centre_px", {b.centre_px.x(), b.centre_px.y()}}, {"radius_px", b.radius_px}, {"rms_px", b.fit.rms_px}}}});
  }
  j["views"] = jv;
  j["left_out"] = rep.left_out;
  j["notes"] = rep.notes;
  if (rep.world_up)
    j["world_up"] = {{"up_in_first_camera", {rep.world_up->up.x(), rep.world_up->up.y(), rep.world_up->up.z()}},
                     {"sigma_deg", rep.world_up->sigma_deg},
                     {"roll_sigma_deg", rep.world_up->roll_sigma_deg},
                     {"roll_deg", rep.world_up->roll_deg}};
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-") {
    double worst = 0;
    for (const ViewPose& p : poses.views) worst = std::max(worst, p.sigma_deg);
    std::cerr << poses.views.size() << " views, " << rep.tracks << " feature tracks, largest orientation sigma "
              << worst << " deg -> " << a.out << "\n";
    for (const std::string& l : rep.left_out) std::cerr << "rsibr orient: left out " << l << "\n";
    for (const std::string& l : rep.notes) std::cerr << "rsibr orient: " << l << "\n";
  }
  return 0;
}

}  // namespace

Runner add_orient(CLI::App& app) {
  auto a = std::make_shared<OrientArgs>();
  CLI::App* c =
      app.add_subcommand("orient", "Solve every view's camera orientation from the features in its chrome ball");
  c->footer(
      "Each image is a merged view (rsibr hdr) of the same ball rig from a different position. The chrome ball is "
      "found in every view (calib/balls/ball_identification.h: the candidate that looks like a mirror), features in it are turned into the world "
      "directions they reflect, matched across views and solved in one least-squares problem; each view's "
      "orientation std dev (degrees) is written with it. The world frame is the first view's camera frame, or with "
      "--up X,Y,Z (the world's up in the first camera's frame; 0,-1,0 for a camera levelled on a tripod) +Y up and "
      "+Z the first camera's forward made horizontal, or with --up auto up estimated from the views (cameras are held "
      "level in roll: the direction most perpendicular to every camera's x axis). A view whose chrome ball is not found "
      "or that shares too few features is left out and reported. A view's name is its header's rsibr.view, else the "
      "file stem.\n"
      "Example: rsibr orient hdr/north.exr hdr/east.exr hdr/south.exr --lens camera.cameramodel --out poses.yaml --up 0,-1,0");
  c->add_option("images", a->images, "Merged view EXRs (rsibr hdr), at least 2")->required();
  c->add_option("--lens", a->lens, "mrcal .cameramodel of the camera")->required();
  c->add_option("--out", a->out, "Output pose file (poses.yaml)")->required();
  c->add_option("--up", a->up,
                "World up X,Y,Z in the first camera's frame, or 'auto' (estimated from the views; "
                "default: world = first camera)");
  c->add_option("--ball", a->balls,
                "VIEW=X,Y,R: the chrome ball of that view is at pixel (X, Y) with radius R (roughly), instead of "
                "the detection (repeatable)");
  c->add_option("--points", a->points,
                "YAML of points picked by hand in two or more views' chrome balls (see the guide): they tie the "
                "views together where the features cannot");
  c->add_option("--json", a->json,
                "Write a JSON summary to FILE ('-' for stdout); when the orientation fails, what it found and why");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report line");
  return [a] { return run_orient(*a); };
}

}  // namespace rsibr::cli
