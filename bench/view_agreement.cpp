// How well the views of a rsibr process run agree where they see the same direction
// (calib/orientation/view_agreement.h), at the run's rotations and at those rotations turned by --perturb-deg
// about random axes: an orientation measure that needs no truth, and the proof that it sees a
// wrong rotation; and where the measure itself is lowest near the solved rotation (a local search),
// how far that lies from it. bench/view_agreement.py runs it on the real two-view sets.
//
//   rsibr_view_agreement RUN_DIR [--perturb-deg 5] [--turns 8] [--json OUT]
#include "calib/lens/far_camera.h"
#include "calib/orientation/pose_file.h"
#include "calib/orientation/view_agreement.h"
#include "calib/view_image.h"
#include "core/lens_model.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

namespace fs = std::filesystem;
using namespace rsibr;

int main(int argc, char** argv) {
  CLI::App app("View agreement of a rsibr process run");
  std::string run, json_out;
  double perturb_deg = 5;
  int turns = 8;
  app.add_option("run", run, "rsibr process output folder")->required();
  app.add_option("--perturb-deg", perturb_deg, "Turn of the perturbed rotations, degrees");
  app.add_option("--turns", turns, "Random axes the second view is turned about");
  app.add_option("--json", json_out, "Write the result as JSON here (default: stdout)");
  CLI11_PARSE(app, argc, argv);
  try {
    const LensModel lens = LensModel::read(fs::path(run) / "lens.cameramodel");
    const PoseSet poses = read_pose_file((fs::path(run) / "poses.yaml").string());
    std::vector<ViewImage> views;
    for (const ViewPose& p : poses.views) {
      if (!p.ball) throw std::invalid_argument(run + "/poses.yaml: view '" + p.name + "' has no chrome ball");
      const std::string file = (fs::path(run) / "hdr" / (p.name + ".exr")).string();
      ViewImage v = read_view_image(file);
      views.push_back(on_lens_canvas(std::move(v), lens, file));
    }
    nlohmann::json out = nlohmann::json::array();
    std::mt19937 rng(1);
    std::normal_distribution<double> g(0, 1);
    for (std::size_t a = 0; a < views.size(); ++a)
      for (std::size_t b = a + 1; b < views.size(); ++b) {
        const ViewPose &pa = poses.views[a], &pb = poses.views[b];
        const ViewAgreement at =
            view_agreement(views[a], *pa.ball, pa.world_from_cam, views[b], *pb.ball, pb.world_from_cam, lens);
        nlohmann::json perturbed = nlohmann::json::array();
        for (int t = 0; t < turns; ++t) {
          const Vec3 axis = Vec3(g(rng), g(rng), g(rng)).normalized();
          const Mat3 turned = pb.world_from_cam * Eigen::AngleAxisd(perturb_deg * kPi / 180, axis).toRotationMatrix();
          const ViewAgreement p =
              view_agreement(views[a], *pa.ball, pa.world_from_cam, views[b], *pb.ball, turned, lens);
          perturbed.push_back({{"mismatch_stops", p.mismatch_stops}, {"overlap", p.overlap}});
        }
        // The measure's own optimum near the solved rotation: a local search over turns of view b
        // about its camera axes, 4 degrees down to a quarter.
        Mat3 best = pb.world_from_cam;
        double best_m = at.mismatch_stops;
        for (double step = 4; step > 0.2; step /= 2)
          for (int it = 0; it < 20; ++it) {
            bool moved = false;
            for (int ax = 0; ax < 3; ++ax)
              for (double sg : {-1.0, 1.0}) {
                const Mat3 t = best * Eigen::AngleAxisd(sg * step * kPi / 180, Vec3::Unit(ax)).toRotationMatrix();
                const double m =
                    view_agreement(views[a], *pa.ball, pa.world_from_cam, views[b], *pb.ball, t, lens).mismatch_stops;
                if (m < best_m) best_m = m, best = t, moved = true;
              }
            if (!moved) break;
          }
        out.push_back(
            {{"views", {pa.name, pb.name}},
             {"sigma_deg", pb.sigma_deg},
             {"overlap", at.overlap},
             {"median_log2_ratio", at.median_log2_ratio},
             {"mismatch_stops", at.mismatch_stops},
             {"perturb_deg", perturb_deg},
             {"perturbed", perturbed},
             {"optimum_mismatch_stops", best_m},
             {"optimum_from_solved_deg", Eigen::AngleAxisd(pb.world_from_cam.transpose() * best).angle() * 180 / kPi}});
      }
    if (json_out.empty())
      std::cout << out.dump(2) << "\n";
    else
      std::ofstream(json_out) << out.dump(2) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "rsibr_view_agreement: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
