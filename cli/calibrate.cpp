// rsibr calibrate: the lens model of a photo set's camera from its chessboard images (calib/intrinsics.h):
// mrgingham corners, mrcal's staged solve, the model chosen by cross-validation, a .cameramodel.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "calib/intrinsics.h"
#include "pipeline/chessboard_problem.h"
#include "capture/photo_set.h"
#include "core/atomic_file.h"
#include "core/progress.h"

#include <cmath>
#include <iostream>
#include <sstream>

namespace rsibr::cli {
namespace {

struct CalibrateArgs {
  std::string photoset, out, json;
  std::vector<std::string> models = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8"};
  bool quiet = false;
};

int run_calibrate(const CalibrateArgs& a) {
  const PhotoSet set = load_photo_set(a.photoset);
  check_output_path(a.out, {a.photoset});
  if (!a.json.empty() && a.json != "-") check_output_path(a.json, {a.photoset});
  std::vector<std::string> missed_files;
  IntrinsicsProblem p;
  {
    Progress progress("corners", !a.quiet && Progress::stderr_is_terminal());
    p = chessboard_problem(set, a.photoset, &missed_files, [&](double f) { progress.update(f); });
    progress.done();
  }
  const nlohmann::json missed = missed_files;

  int chosen = 0;
  const std::vector<ModelScore> scores = cross_validate_models(p, a.models, &chosen);
  const IntrinsicsFit fit = fit_intrinsics(p, a.models[chosen]);
  fit.lens.write(a.out);

  // Residual pattern: mean residual vector and RMS per cell of a 4 x 3 grid over the image.
  const int gx = 4, gy = 3;
  std::vector<Vec2> sum(gx * gy, Vec2::Zero());
  std::vector<double> sum2(gx * gy, 0.0);
  std::vector<int> count(gx * gy, 0);
  nlohmann::json boards = nlohmann::json::array();
  const int per_board = p.corners_x * p.corners_y;
  for (std::size_t b = 0; b < p.boards.size(); ++b) {
    double s2 = 0;
    for (int k = 0; k < per_board; ++k) {
      const Vec2& r = fit.residuals[b * per_board + k];
      const Vec2& q = p.boards[b].corners[k];
      const int cx = std::clamp(static_cast<int>(q.x() / p.width * gx), 0, gx - 1);
      const int cy = std::clamp(static_cast<int>(q.y() / p.height * gy), 0, gy - 1);
      sum[cy * gx + cx] += r;
      sum2[cy * gx + cx] += r.squaredNorm();
      ++count[cy * gx + cx];
      s2 += r.squaredNorm();
    }
    boards.push_back({{"file", p.boards[b].name}, {"rms_px", std::sqrt(s2 / per_board)}});
  }
  nlohmann::json pattern = nlohmann::json::array();
  for (int c = 0; c < gx * gy; ++c) {
    const Vec2 m = count[c] ? Vec2(sum[c] / count[c]) : Vec2::Zero();
    pattern.push_back({{"cell", {c % gx, c / gx}},
                       {"corners", count[c]},
                       {"mean_residual_px", {m.x(), m.y()}},
                       {"rms_px", count[c] ? std::sqrt(sum2[c] / count[c]) : 0.0}});
  }
  nlohmann::json j;
  j["photoset"] = a.photoset;
  j["out"] = a.out;
  j["image_size"] = {p.width, p.height};
  j["boards_found"] = p.boards.size();
  j["boards_missed"] = missed;
  j["model"] = a.models[chosen];
  j["intrinsics"] = fit.lens.intrinsics();
  j["rms_px"] = fit.rms_px;
  j["outliers"] = fit.outliers;
  nlohmann::json sc = nlohmann::json::array();
  for (const ModelScore& s : scores)
    sc.push_back({{"model", s.model}, {"held_out_rms_px", s.held_out_rms_px}, {"fit_rms_px", s.fit_rms_px}});
  j["models"] = sc;
  j["boards"] = boards;
  j["residual_grid_4x3"] = pattern;
  write_summary(a.json, j);
  if (!a.quiet && a.json != "-")
    std::cerr << a.models[chosen] << ": RMS " << fit.rms_px << " px over " << p.boards.size() << " boards -> " << a.out
              << "\n";
  return 0;
}

}  // namespace

Runner add_calibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* c = app.add_subcommand("calibrate", "Calibrate the lens from a photo set's chessboards (mrgingham + mrcal)");
  c->footer(
      "Finds the chessboard corners of every image listed under chessboards: in photoset.yaml (mrgingham), seeds a "
      "pinhole core and the board poses (OpenCV), and solves with mrcal in two stages (core and poses, then "
      "everything with regularisation and outlier rejection). Each --model is fitted to one half of the boards and "
      "scored on the other (both ways); the simplest within 5% of the best held-out RMS is written. The JSON reports "
      "every model's scores, the RMS per board and the residual pattern over a 4x3 grid of the image.\n"
      "Example: rsibr calibrate shoot/photoset.yaml --out shoot/camera.cameramodel --json -");
  c->add_option("photoset", a->photoset, "photoset.yaml or the folder holding it")->required();
  c->add_option("--out", a->out, "Output .cameramodel")->required();
  c->add_option("--model", a->models, "Candidate mrcal models, simplest first (repeatable)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report line");
  return [a] { return run_calibrate(*a); };
}

}  // namespace rsibr::cli
