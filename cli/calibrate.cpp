// rsibr calibrate: the lens model of a photo set's camera from its chessboard images (calib/lens/intrinsics.h):
// mrgingham corners, mrcal's staged solve, the model chosen by cross-validation, a .cameramodel.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "calib/lens/intrinsics.h"
#include "calib/lens/photo_optics.h"
#include "formats/atomic_file.h"
#include "formats/output_plan.h"
#include "formats/photo_set.h"
#include "core/progress.h"
#include "hdr/bracket_set.h"
#include "pipeline/chessboard_problem.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

namespace rsibr::cli {
namespace {

struct CalibrateArgs {
  std::string photoset, out, json;
  std::vector<std::string> models = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8", "splined"};
  bool quiet = false;
};

// The splined candidate ("splined" among --model) needs boards over most of the image: a spline
// control point that no corner constrains is set by mrcal's regularisation alone, and the
// cross-validation halves must each constrain the spline. Cells of an 8 x 6 grid over the image.
constexpr int kSplineNx = 8;
constexpr int kCoverageCellsX = 8, kCoverageCellsY = 6;
constexpr double kMinSplineCoverage = 0.6;
constexpr std::size_t kMinSplineBoards = 8;

// The .cameramodel text mrcal writes, preceded by '#' comment lines (mrcal's reader skips them).
void write_with_comment(const LensModel& lens, const std::string& out, const std::string& comment) {
  lens.write(out);
  std::ifstream in(out, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  write_text_atomically(out, comment + text.str());  // renamed over the model: never half a file
}

// No chessboards: the lens from the first photo's metadata (calib/lens/photo_optics.h metadata_lens),
// lensfun's profile of the lens its EXIF names, else the EXIF pinhole, with its stated sigma.
int calibrate_from_metadata(const CalibrateArgs& a, const PhotoSet& set, OutputPlan& outputs, const std::string& model,
                            const std::string& json) {
  if (set.views.empty() || set.views[0].brackets.empty())
    throw std::invalid_argument(a.photoset + ": no chessboards and no photos to read a focal length from");
  const BracketSet b = load_brackets(set.views[0], true);
  const std::filesystem::path photo = set.views[0].brackets[0].file;
  const std::optional<MetadataLens> m = metadata_lens(photo, b.cols(), b.rows());
  if (!m)
    throw std::invalid_argument(photo.string() +
                                ": no chessboards listed and no usable focal length in the photo's "
                                "metadata (FocalLengthIn35mmFilm, or FocalLength of a camera lensfun knows)");
  std::ostringstream comment;
  comment << std::setprecision(4) << "# rsibr calibrate: no chessboards; " << m->source << " (" << m->lens.source
          << ")\n# focal length " << m->lens.focal_px << " px, 1 sigma " << 100 * m->lens.sigma_relative << "%\n";
  write_with_comment(m->lens.lens, model, comment.str());
  nlohmann::json j = {{"photoset", a.photoset},
                      {"out", a.out},
                      {"image_size", {b.cols(), b.rows()}},
                      {"source", m->source},
                      {"model", m->lens.lens.name()},
                      {"intrinsics", m->lens.lens.intrinsics()},
                      {"focal_px", m->lens.focal_px},
                      {"focal_sigma_relative", m->lens.sigma_relative},
                      {"focal_from", m->lens.source},
                      {"photo", photo.string()},
                      {"camera", m->optics.make + " " + m->optics.model},
                      {"lens", m->optics.lens}};
  if (!m->lensfun_why.empty()) j["lensfun"] = m->lensfun_why;
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-")
    std::cerr << m->lens.lens.name() << " from the photos' metadata (" << m->source << ", f " << m->lens.focal_px
              << " px +- " << 100 * m->lens.sigma_relative << "%) -> " << a.out << "\n";
  return 0;
}

int run_calibrate(const CalibrateArgs& a) {
  const PhotoSet set = load_photo_set(a.photoset);
  OutputPlan outputs(set.files());
  const std::string model = outputs.file(a.out), json = outputs.file(a.json);
  if (!set.chessboards) return calibrate_from_metadata(a, set, outputs, model, json);
  std::vector<std::string> missed_files;
  IntrinsicsProblem p;
  {
    Progress progress("corners", !a.quiet && Progress::stderr_is_terminal());
    p = chessboard_problem(set, a.photoset, &missed_files, [&](double f) { progress.update(f); });
    progress.done();
  }
  const nlohmann::json missed = missed_files;

  // "splined" -> a spline over the seed's field of view, or skipped (with the reason) when the boards
  // do not cover enough of the image.
  std::vector<std::string> models;
  nlohmann::json skipped = nlohmann::json::array();
  const double coverage = board_coverage(p, kCoverageCellsX, kCoverageCellsY);
  for (const std::string& m : a.models) {
    if (m != "splined") {
      models.push_back(m);
      continue;
    }
    std::ostringstream why;
    if (coverage < kMinSplineCoverage)
      why << "boards cover " << std::lround(100 * coverage) << "% of the image's " << kCoverageCellsX << "x"
          << kCoverageCellsY << " cells, the spline needs " << std::lround(100 * kMinSplineCoverage) << "%";
    else if (p.boards.size() < kMinSplineBoards)
      why << p.boards.size() << " boards, the spline needs " << kMinSplineBoards << " (4 per cross-validation half)";
    if (why.str().empty())
      models.push_back(splined_candidate(p, kSplineNx));
    else
      skipped.push_back({{"model", "splined"}, {"reason", why.str()}});
  }
  if (models.empty()) throw std::invalid_argument(a.photoset + ": no lens model left to fit (" + skipped.dump() + ")");

  int chosen = 0;
  const std::vector<ModelScore> scores = cross_validate_models(p, models, &chosen);
  const IntrinsicsFit fit = fit_intrinsics(p, models[chosen]);

  // Projection uncertainty (calib/lens/intrinsics.h: projection_covariance) at a 3 x 3 grid of pixels:
  // 1-sigma along the worst direction.
  nlohmann::json points = nlohmann::json::array();
  double worst_sigma = 0;
  for (const double fy : {0.1, 0.5, 0.9})
    for (const double fx : {0.1, 0.5, 0.9}) {
      const Vec2 q(fx * (p.width - 1), fy * (p.height - 1));
      const Eigen::Matrix2d c = projection_covariance(fit.lens, fit.intrinsics_covariance, fit.lens.unproject(q));
      const double s = std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(c).eigenvalues()(1)));
      worst_sigma = std::max(worst_sigma, s);
      points.push_back({{"pixel", {q.x(), q.y()}}, {"sigma_px", s}, {"covariance_px2", {c(0, 0), c(0, 1), c(1, 1)}}});
    }
  nlohmann::json intrinsics_sigma = nlohmann::json::array();
  for (Eigen::Index k = 0; k < fit.intrinsics_covariance.rows(); ++k)
    intrinsics_sigma.push_back(std::sqrt(std::max(0.0, fit.intrinsics_covariance(k, k))));

  std::ostringstream comment;
  comment << std::setprecision(4) << "# rsibr calibrate: " << models[chosen] << " chosen by cross-validation over "
          << p.boards.size() << " boards\n# RMS " << fit.rms_px << " px, corner noise " << fit.noise_sigma_px
          << " px per axis, " << fit.outliers
          << " outliers\n# projection uncertainty (1 sigma, 3x3 grid over the image): "
          << "worst " << worst_sigma << " px, centre " << points[4]["sigma_px"].get<double>() << " px\n";
  write_with_comment(fit.lens, model, comment.str());

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
  j["model"] = models[chosen];
  j["intrinsics"] = fit.lens.intrinsics();
  j["rms_px"] = fit.rms_px;
  j["outliers"] = fit.outliers;
  nlohmann::json sc = nlohmann::json::array();
  for (const ModelScore& s : scores)
    sc.push_back({{"model", s.model}, {"held_out_rms_px", s.held_out_rms_px}, {"fit_rms_px", s.fit_rms_px}});
  j["models"] = sc;
  j["skipped_models"] = skipped;
  j["board_coverage"] = coverage;
  j["uncertainty"] = {
      {"noise_sigma_px", fit.noise_sigma_px},
      {"intrinsics_sigma", intrinsics_sigma},
      {"projection", points},
      {"worst_projection_sigma_px", worst_sigma},
      {"note",
       "1-sigma of the projection of a fixed camera-frame direction, propagated from the intrinsics covariance "
       "(board poses marginalised); includes the principal-point part that mrcal's uncertainty attributes to a "
       "shift of the reference frame; for splined models excludes the small rotation that regularisation pins"}};
  j["boards"] = boards;
  j["residual_grid_4x3"] = pattern;
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-")
    std::cerr << models[chosen] << ": RMS " << fit.rms_px << " px over " << p.boards.size() << " boards -> " << a.out
              << "\n";
  return 0;
}

}  // namespace

Runner add_calibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* c =
      app.add_subcommand("calibrate", "Calibrate the lens from a photo set's chessboards (mrgingham + mrcal)");
  c->footer(
      "Finds the chessboard corners of every image listed under chessboards: in photoset.yaml (mrgingham), seeds a "
      "pinhole core and the board poses (OpenCV), and solves with mrcal in two stages (core and poses, then "
      "everything with regularisation and outlier rejection). Each --model is fitted to one half of the boards and "
      "scored on the other (both ways); the simplest within 5% of the best held-out RMS is written. The JSON reports "
      "every model's scores, the RMS per board, the residual pattern over a 4x3 grid of the image and the "
      "uncertainty: the corner noise estimated from the residuals, the intrinsics' standard deviations (board poses "
      "marginalised) and the projection's 1-sigma at a 3x3 grid of pixels (also in the .cameramodel's comment "
      "header). The candidate 'splined' is LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8 over the seed's field of "
      "view, fitted from a LENSMODEL_STEREOGRAPHIC core; it is skipped (with the reason in the JSON) when the boards "
      "cover less than 60% of an 8x6 grid over the image or number fewer than 8. With no chessboards listed, the lens "
      "comes from the first photo's metadata: lensfun's distortion profile of the camera and lens its EXIF names, "
      "else a pinhole from the 35 mm-equivalent focal length, with the focal length's stated 1-sigma in the JSON "
      "(rsibr process then refines it from the balls' outlines).\n"
      "Example: rsibr calibrate shoot/photoset.yaml --out shoot/camera.cameramodel --json -");
  c->add_option("photoset", a->photoset, "photoset.yaml or the folder holding it")->required();
  c->add_option("--out", a->out, "Output .cameramodel")->required();
  c->add_option("--model", a->models,
                "Candidate mrcal models, simplest first (repeatable; 'splined' for the automatic spline)")
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            if (name == "splined") return "";
            try {
              LensModel::check_name(name);  // before any work, and before mrcal could assert on it
            } catch (const std::invalid_argument& e) {
              return e.what();
            }
            return "";
          },
          ""));
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report line");
  return [a] { return run_calibrate(*a); };
}

}  // namespace rsibr::cli
