// The geometry of one rsibr process run against its synthetic shoot's truth (bench/geometry_robustness.py
// runs held-out shoots through synth and process and writes the docs/tradeoffs.md section "Robust
// geometry (rsibr process on shoots)").
//
//   rsibr_geometry_robustness SYNTH_DIR RUN_DIR [REFERENCE_RUN_DIR]
//
// JSON on stdout:
//   balls        per listed ball: found, wrong (centre farther than a fifth of its radius from the
//                truth's), missing (with the views), cut (found and flagged / truly cut)
//   views        oriented / listed
//   tilt_deg     angle between the run's +Y and the true up, through the oriented views' rotations
//                (true_from_run = R_true R_run^T, averaged as up vectors over the views within 2 degrees
//                of their medoid); sigma_deg the run's own
//   misoriented  the other views, with their angle from the medoid (degrees)
//   left_out_of_up  the views the run left out of its world-up estimate (their balls disagree with the rig)
//   vignetting   the corner's fall-off estimated and true, in stops
//   grey         per view: log RMS (stops) of the captured grey map against the true one after the
//                global gain fit, the map moved into the truth's world through the view's true
//                rotation; and the worst
//   reference    with REFERENCE_RUN_DIR (the same shoot processed from the true scene radiance, poses and
//                lens: every physical effect on the grey ball, the photographer's and the other balls'
//                occlusion included, and none of the pipeline's errors): the grey maps against that
//                run's, per view after the gain fit: the pipeline's own error
#include "calib/orientation/pose_file.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "hdr/vignetting.h"
#include "pipeline/pose_input.h"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

namespace fs = std::filesystem;
using namespace rsibr;

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::cerr << "usage: rsibr_geometry_robustness SYNTH_DIR RUN_DIR [REFERENCE_RUN_DIR]\n";
    return 2;
  }
  const fs::path syn = argv[1], run = argv[2];
  try {
    const YAML::Node truth = YAML::LoadFile((syn / "truth" / "truth.yaml").string());
    nlohmann::json extract;
    std::ifstream(run / "steps" / "extract.json") >> extract;
    nlohmann::json orient, hdr;
    std::ifstream(run / "steps" / "orient.json") >> orient;
    std::ifstream(run / "steps" / "hdr.json") >> hdr;
    const LensModel lens = LensModel::read(run / "camera.cameramodel");
    // Truth per view and ball: centre pixel and image radius (from the distance and diameter).
    std::map<std::string, std::map<std::string, std::pair<Vec2, double>>> where;
    std::map<std::string, double> diameter;
    for (const auto& b : truth["balls"]) diameter[b["name"].as<std::string>()] = b["diameter_m"].as<double>();
    const double f = lens.intrinsics().empty() ? 1 : lens.intrinsics()[0];
    for (const auto& v : truth["views"])
      for (const auto& b : v["balls"]) {
        const std::string name = b["name"].as<std::string>();
        const double d = b["distance_m"].as<double>(), r = 0.5 * diameter[name];
        where[v["name"].as<std::string>()][name] = {
            Vec2(b["centre_px"][0].as<double>(), b["centre_px"][1].as<double>()), f * r / std::sqrt(d * d - r * r)};
      }
    nlohmann::json out, balls = nlohmann::json::object();
    for (const auto& v : extract["summary"]["views"])
      for (const auto& b : v["balls"]) {
        const std::string name = b["ball"], view = v["name"];
        auto& j = balls[name];
        if (!j.contains("found"))
          j = {{"found", 0}, {"wrong", 0}, {"missing", nlohmann::json::array()}, {"cut_flagged", 0}, {"cut_true", 0}};
        const auto [c, r] = where[view][name];
        const bool truly_cut =
            c.x() - r < -0.5 || c.y() - r < -0.5 || c.x() + r > lens.width() - 0.5 || c.y() + r > lens.height() - 0.5;
        if (!b.contains("centre_px")) {
          j["missing"].push_back(view + ": " + b["status"].get<std::string>() + " (" + b.value("note", "") + ")");
          continue;
        }
        j["found"] = j["found"].get<int>() + 1;
        const Vec2 p(b["centre_px"][0].get<double>(), b["centre_px"][1].get<double>());
        if ((p - c).norm() > 0.2 * r) j["wrong"] = j["wrong"].get<int>() + 1;
        j["cut_flagged"] = j["cut_flagged"].get<int>() + int(b.value("cut", false) && truly_cut);
        j["cut_true"] = j["cut_true"].get<int>() + int(truly_cut);
      }
    for (const auto& v : extract["summary"]["views"])
      if (v.contains("left_out"))
        balls["*"]["missing"].push_back(v["name"].get<std::string>() + ": " + v["left_out"].get<std::string>());
    out["balls"] = balls;
    const PoseSet est = read_pose_file((run / "poses.yaml").string());
    const PoseSet tru = read_given_poses((syn / "truth" / "truth.yaml").string());
    out["views"] = {{"oriented", est.views.size()}, {"listed", tru.views.size()}};
    // Per view true_from_run = R_true R_run^T (one rotation for a well-oriented set). The medoid
    // (least summed angle to the others) and the views within 2 degrees of it give the run's world;
    // the rest are misoriented, listed with their angle from the medoid.
    std::vector<Mat3> q;
    for (const ViewPose& v : est.views) q.push_back(tru.find(v.name)->world_from_cam * v.world_from_cam.transpose());
    auto rot_deg = [](const Mat3& a, const Mat3& b) {
      return std::acos(std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0)) * 180 / kPi;
    };
    std::size_t medoid = 0;
    double best = 1e300;
    for (std::size_t i = 0; i < q.size(); ++i) {
      double sum = 0;
      for (const Mat3& r : q) sum += rot_deg(q[i], r);
      if (sum < best) best = sum, medoid = i;
    }
    Vec3 up = Vec3::Zero();
    nlohmann::json misoriented = nlohmann::json::array();
    for (std::size_t i = 0; i < q.size(); ++i) {
      const double d = rot_deg(q[i], q[medoid]);
      if (d <= 2.0)
        up += q[i] * Vec3(0, 1, 0);
      else
        misoriented.push_back({{"view", est.views[i].name}, {"deg", d}});
    }
    out["tilt_deg"] = angle_between(up, Vec3(0, 1, 0)) * 180 / kPi;
    out["misoriented"] = misoriented;
    out["left_out_of_up"] = orient["summary"].contains("solve") && orient["summary"]["solve"].is_object() &&
                                    orient["summary"]["solve"].contains("left_out_of_up")
                                ? orient["summary"]["solve"]["left_out_of_up"]
                                : nlohmann::json::array();
    out["sigma_deg"] = orient["summary"].contains("world_up") && orient["summary"]["world_up"].is_object()
                           ? orient["summary"]["world_up"]["sigma_deg"]
                           : nlohmann::json(nullptr);
    out["gauge"] = est.gauge;
    // Vignetting: the truth's a (v = 1 - a r^2) or polynomial, at the corner.
    Vignetting tv;
    const YAML::Node tvig = truth["camera"]["vignetting"];
    if (tvig.IsSequence()) {
      for (int i = 0; i < 3; ++i) tv.k[std::size_t(i)] = tvig[i].as<double>();
    } else {
      tv.k = {-tvig.as<double>(), 0, 0};
    }
    out["vignetting"] = {{"true_corner_stops", tv.corner_stops()},
                         {"estimated_corner_stops", hdr["summary"]["vignetting"]["model"]["corner_stops"]},
                         {"source", hdr["summary"]["vignetting"]["model"]["source"]}};
    // Grey maps against the truth.
    nlohmann::json grey = nlohmann::json::array();
    double worst = 0;
    for (const auto& [name, d] : diameter) {
      (void)d;
      bool is_grey = false;
      for (const auto& b : truth["balls"])
        if (b["name"].as<std::string>() == name) is_grey = b["kind"].as<std::string>() == "grey";
      if (!is_grey) continue;
      MapSet m = read_map_set((run / "maps" / ("captured-" + name + ".exr")).string());
      for (MapView& v : m.views) {
        const std::string img = v.image;
        v.world_from_view =
            tru.find(img)->world_from_cam * est.find(img)->world_from_cam.transpose() * v.world_from_view;
        v.view = v.world_from_view.col(2);
      }
      CompareOptions co;
      co.view_tolerance_deg = 2;
      const Comparison c = compare_map_sets(m, read_map_set((syn / "truth" / "maps" / (name + ".exr")).string()), co);
      for (const PairComparison& p : c.pairs) {
        grey.push_back({{"ball", name}, {"view", m.views[p.index_a].image}, {"stops", p.after.log_rms_stops}});
        worst = std::max(worst, p.after.log_rms_stops);
      }
      out["grey_overall_stops"] = c.after.log_rms_stops;
      if (argc == 4) {
        // The views both runs kept (each may leave out different ones).
        MapSet ref = read_map_set((fs::path(argv[3]) / "maps" / ("captured-" + name + ".exr")).string());
        auto has = [](const MapSet& s, const std::string& img) {
          return std::any_of(s.views.begin(), s.views.end(), [&](const MapView& v) { return v.image == img; });
        };
        MapSet both;
        for (const MapView& v : m.views)
          if (has(ref, v.image)) both.views.push_back(v);
        std::erase_if(ref.views, [&](const MapView& v) { return !has(both, v.image); });
        const Comparison r = compare_map_sets(both, ref, co);
        nlohmann::json per = nlohmann::json::array();
        double rw = 0;
        for (const PairComparison& p : r.pairs) {
          per.push_back({{"view", both.views[p.index_a].image}, {"stops", p.after.log_rms_stops}});
          rw = std::max(rw, p.after.log_rms_stops);
        }
        out["reference"] = {
            {"ball", name}, {"views", per}, {"worst_stops", rw}, {"overall_stops", r.after.log_rms_stops}};
      }
    }
    out["grey"] = grey;
    out["grey_worst_stops"] = worst;
    std::cout << out.dump(2) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rsibr_geometry_robustness: " << e.what() << "\n";
    return 1;
  }
}
