#include "pipeline/orient_step.h"

#include "calib/orientation/pair_matches_picture.h"
#include "calib/orientation/view_orientation.h"
#include "formats/atomic_folder.h"
#include "pipeline/orientation_json.h"

#include <algorithm>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

nlohmann::json world_up_json(const WorldUp& w) {
  return {{"up_in_first_camera", {w.up.x(), w.up.y(), w.up.z()}},
          {"sigma_deg", w.sigma_deg},
          {"roll_sigma_deg", w.roll_sigma_deg},
          {"roll_sigma_estimated", w.roll_sigma_estimated},
          {"roll_deg", w.roll_deg},
          {"tilt_from_first_camera_deg", w.tilt_from_first_deg},
          {"lines", w.lines}};
}

// The picture's name as the summary gives it: relative to the pictures folder's parent (the run).
std::string summary_name(const OrientStep& s, const fs::path& f) {
  return fs::relative(f, s.pictures.parent_path()).string();
}

}  // namespace

OrientedViews run_orient_step(const OrientStep& s, nlohmann::json* failed) {
  if (!s.lens) throw std::invalid_argument("orient: no lens");
  if (!s.read_view) throw std::invalid_argument("orient: no reader of the merged views");
  const LensModel& lens = *s.lens;
  OrientedViews out;
  PoseSet poses;
  std::string source;
  nlohmann::json solve, left_out = nlohmann::json::array(), notes = nlohmann::json::array(), up = nullptr;
  std::vector<std::string> names;
  std::vector<ViewImage> images;
  auto load_images = [&] {
    for (const std::string& v : s.views) {
      names.push_back(v);
      images.push_back(s.read_view(v));
    }
  };
  ViewOrientationOptions vo;
  vo.listed = s.found.listed;
  // The balls step's candidates through this lens: nothing is searched again.
  for (const std::string& v : s.views) {
    const FoundView* fv = s.found.find(v);
    if (!fv) throw std::invalid_argument("orient: the balls step found no view '" + v + "' (rerun it)");
    vo.candidates.push_back(candidates_for_lens(*fv, lens));
  }
  if (s.points) vo.points = *s.points;
  ViewOrientationReport report;
  if (s.given) {
    source = "given (" + s.given_file + ")";
    poses.gauge = s.given->gauge;
    for (const std::string& v : s.views) {
      const ViewPose* p = s.given->find(v);
      if (!p) throw std::invalid_argument(s.given_file + ": no pose for view '" + v + "'");
      poses.views.push_back(*p);
    }
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
    if (poses.gauge == "first-view" && !s.up && s.estimate_up) {
      up = world_up_json(level_pose_set(poses));
      source += ", levelled by the estimated up";
    }
  } else {
    load_images();
    vo.up = s.up;
    vo.estimate_up = s.estimate_up;
    // Per pair, the features that tied the views (or failed to): PICTURES/A--B.png.
    const auto pair_pictures = [&] {
      nlohmann::json listed = nlohmann::json::array();
      if (s.pictures.empty()) return listed;
      for (const PairOrientation& p : report.pairs) {
        const auto image = [&](const std::string& name) -> const cv::Mat& {
          return images[std::size_t(std::find(names.begin(), names.end(), name) - names.begin())].radiance;
        };
        fs::create_directories(s.pictures);
        out.pictures.push_back(file_in_folder(s.pictures, p.a + "--" + p.b + ".png"));
        write_pair_matches_picture(out.pictures.back(), image(p.a), image(p.b), p);
        listed.push_back(summary_name(s, out.pictures.back()));
      }
      return listed;
    };
    try {
      poses = orient_views(names, images, lens, vo, &report);
    } catch (const std::exception&) {
      // What the solve saw before it stopped, for the failure record and the pictures.
      if (failed)
        *failed = {{"left_out", report.left_out},
                   {"notes", report.notes},
                   {"solve",
                    {{"features", report.features},
                     {"pairs", pair_orientation_json(report.pairs)},
                     {"pair_pictures", pair_pictures()}}}};
      throw;
    }
    const nlohmann::json pictures = pair_pictures();
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
  out.poses.gauge = poses.gauge;
  for (const std::string& v : s.views)
    if (const ViewPose* p = poses.find(v)) out.poses.views.push_back(*p);
  nlohmann::json views = nlohmann::json::array();
  for (const ViewPose& p : out.poses.views) {
    const Vec3 forward = p.world_from_cam.col(2);
    nlohmann::json vj = {
        {"name", p.name}, {"sigma_deg", p.sigma_deg}, {"forward", {forward.x(), forward.y(), forward.z()}}};
    if (p.ball) {
      const Vec2 cp = lens.project(p.ball->axis);
      vj["chrome_centre_px"] = {cp.x(), cp.y()};
    }
    views.push_back(vj);
  }
  out.summary = {{"source", source},     {"gauge", out.poses.gauge}, {"views", views}, {"solve", solve},
                 {"left_out", left_out}, {"notes", notes},           {"world_up", up}};
  return out;
}

}  // namespace rsibr
