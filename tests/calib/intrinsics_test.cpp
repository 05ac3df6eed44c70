// calib/lens/intrinsics.h: mrcal's solve recovers a known lens from noisy corners of boards posed by
// capture/chessboard.h; cross-validation picks the true model family; mrgingham finds the corners.
#include "calib/lens/intrinsics.h"

#include "capture/chessboard.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <filesystem>
#include <random>

#include <unistd.h>

namespace rsibr {
namespace {

constexpr int kCorners = 10;
constexpr double kSpacing = 0.03;

// True corners of `count` boards seen through `lens`, plus Gaussian noise sigma (px).
IntrinsicsProblem board_problem(const LensModel& lens, int count, double sigma, std::uint64_t seed) {
  const RayTable rays(lens);
  SynthChessboards boards;
  boards.count = count;
  boards.corners = kCorners;
  boards.spacing_m = kSpacing;
  IntrinsicsProblem p;
  p.width = lens.width();
  p.height = lens.height();
  p.corners_x = p.corners_y = kCorners;
  p.spacing_m = kSpacing;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, sigma);
  for (int i = 0; i < count; ++i) {
    const ChessboardShot shot = render_chessboard(lens, rays, boards, i, seed, 1);
    ChessboardObservation o;
    o.name = "board" + std::to_string(i);
    for (const Vec2& c : shot.corners) o.corners.push_back(c + Vec2(g(rng), g(rng)));
    p.boards.push_back(o);
  }
  return p;
}

LensModel opencv4_truth() {
  return LensModel("LENSMODEL_OPENCV4", {520, 523, 322.4, 236.8, -0.15, 0.04, 0.001, -0.0006}, 640, 480);
}

// Largest pixel difference between two lenses where the boards were seen, as mrcal compares
// lenses: each observed corner's ray through `a`, turned by the rotation that best aligns a's rays
// with b's (Kabsch; a planar target leaves the principal point and a small rotation of the camera
// frame nearly interchangeable, so only the rotation-free difference is determined), projected
// through `b`.
Mat3 best_rotation(const LensModel& a, const LensModel& b, const IntrinsicsProblem& p) {
  Mat3 h = Mat3::Zero();
  for (const auto& board : p.boards)
    for (const Vec2& q : board.corners) h += b.unproject(q) * a.unproject(q).transpose();
  Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

double max_projection_difference(const LensModel& a, const LensModel& b, const IntrinsicsProblem& p) {
  Mat3 h = Mat3::Zero();
  for (const auto& board : p.boards)
    for (const Vec2& q : board.corners) h += b.unproject(q) * a.unproject(q).transpose();
  Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  const Mat3 r = svd.matrixU() * d * svd.matrixV().transpose();
  double worst = 0;
  for (const auto& board : p.boards)
    for (const Vec2& q : board.corners) worst = std::max(worst, (b.project(r * a.unproject(q)) - q).norm());
  return worst;
}

// Corner noise sigma on 12 boards of 100 corners: the fitted lens projects like the true one
// wherever the boards were seen, to within a difference that scales with the noise (no floor: no
// bias from the seed, the staging or mrcal's regularisation): <= 1.5 sigma at sigma = 0.1 px and
// 0.01 px; and the RMS residual is the noise level.
TEST(Intrinsics, FitRecoversTheTrueLensToWithinItsNoise) {
  const LensModel truth = opencv4_truth();
  for (const double sigma : {0.1, 0.01}) {
    const IntrinsicsProblem p = board_problem(truth, 12, sigma, 3);
    const IntrinsicsFit fit = fit_intrinsics(p, "LENSMODEL_OPENCV4");
    const double diff = max_projection_difference(truth, fit.lens, p);
    std::printf("  sigma %.2f: OPENCV4 RMS %.4f px, outliers %d, max projection difference %.4f px, f = %.3f %.3f\n",
                sigma, fit.rms_px, fit.outliers, diff, fit.lens.intrinsics()[0], fit.lens.intrinsics()[1]);
    EXPECT_LT(diff, 1.5 * sigma);
    // RMS of 2-D residuals with per-axis sigma: sigma * sqrt(2) (1200 corners, ~80 parameters).
    EXPECT_NEAR(fit.rms_px, sigma * std::sqrt(2.0), 0.15 * sigma);
    EXPECT_EQ(fit.residuals.size(), 1200u);
    EXPECT_EQ(fit.rt_cam_board.size(), 12u);
  }
}

// A distorted lens: pinhole's held-out RMS is far worse, OPENCV4 wins over OPENCV8 (as good, fewer
// parameters). A pinhole lens: the pinhole wins.
TEST(Intrinsics, CrossValidationChoosesTheTrueModelFamily) {
  const std::vector<std::string> models = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8"};
  {
    const IntrinsicsProblem p = board_problem(opencv4_truth(), 12, 0.1, 5);
    int chosen = -1;
    const auto scores = cross_validate_models(p, models, &chosen);
    for (const auto& s : scores)
      std::printf("  distorted: %-20s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px,
                  s.fit_rms_px);
    EXPECT_EQ(models.at(chosen), "LENSMODEL_OPENCV4");
    EXPECT_GT(scores[0].held_out_rms_px, 3 * scores[1].held_out_rms_px);
  }
  {
    const IntrinsicsProblem p = board_problem(LensModel::pinhole(500, 640, 480), 12, 0.1, 6);
    int chosen = -1;
    const auto scores = cross_validate_models(p, models, &chosen);
    for (const auto& s : scores)
      std::printf("  pinhole:   %-20s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px,
                  s.fit_rms_px);
    EXPECT_EQ(models.at(chosen), "LENSMODEL_PINHOLE");
  }
}

TEST(Intrinsics, TooFewBoardsOrWrongCornerCountsAreRefused) {
  IntrinsicsProblem p = board_problem(opencv4_truth(), 3, 0.1, 7);
  p.boards.pop_back();
  EXPECT_THROW(fit_intrinsics(p, "LENSMODEL_OPENCV4"), std::invalid_argument);
  p = board_problem(opencv4_truth(), 3, 0.1, 7);
  p.boards[1].corners.pop_back();
  try {
    fit_intrinsics(p, "LENSMODEL_OPENCV4");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("board1"), std::string::npos) << e.what();
  }
  p = board_problem(opencv4_truth(), 3, 0.1, 7);
  EXPECT_THROW(fit_intrinsics(p, "LENSMODEL_FISHEYE9"), std::invalid_argument);
}

// mrgingham (linked as a library) on a rendered board: every corner within 0.3 px of the truth.
TEST(Intrinsics, MrginghamFindsTheRenderedCorners) {
  const LensModel lens = opencv4_truth();
  const RayTable rays(lens);
  SynthChessboards boards;
  boards.count = 1;
  boards.corners = kCorners;
  boards.spacing_m = kSpacing;
  const ChessboardShot shot = render_chessboard(lens, rays, boards, 0, 9, 3);
  // sRGB-like 8-bit codes, as a camera writes them.
  cv::Mat encoded;
  cv::pow(shot.reflectance, 1 / 2.2, encoded);
  cv::Mat gray;
  encoded.convertTo(gray, CV_8U, 255.0);
  const auto found = find_chessboard(gray, kCorners);
  ASSERT_TRUE(found.has_value());
  ASSERT_EQ(found->size(), shot.corners.size());
  double worst = 0;
  for (const Vec2& f : *found) {
    double nearest = 1e9;
    for (const Vec2& t : shot.corners) nearest = std::min(nearest, (f - t).norm());
    worst = std::max(worst, nearest);
  }
  std::printf("  mrgingham: worst corner %.3f px\n", worst);
  EXPECT_LT(worst, 0.3);
  // A blank image has no board.
  EXPECT_FALSE(find_chessboard(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), kCorners).has_value());
}

// A wide lens (about 125 degrees across) with strong barrel distortion: the radial factor
// (1 + 0.1 r^2) / (1 + 0.4 r^2) is monotonic for every r (its derivative's numerator 1 - 0.1 r^2 +
// 0.04 r^4 has no real root), so the lens is invertible over the whole image.
LensModel wide_opencv8_truth() {
  return LensModel("LENSMODEL_OPENCV8", {300, 301, 322.0, 236.5, 0.1, 0, 0.0005, -0.0003, 0, 0.4, 0, 0}, 640, 480);
}

// The splined model is a full citizen of core/lens_model.h: written to a .cameramodel and read back
// (mrcal's writer keeps 6 decimals: every parameter within 5e-7, every projection within 1e-3 px),
// projection and unprojection inverse to each other across the image.
TEST(Intrinsics, SplinedModelRoundTripsThroughACameramodel) {
  const IntrinsicsProblem p = board_problem(wide_opencv8_truth(), 6, 0.1, 11);
  const std::string name = splined_candidate(p, 8);
  std::printf("  candidate %s\n", name.c_str());
  EXPECT_EQ(name.rfind("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=", 0), 0u) << name;
  const IntrinsicsFit fit = fit_intrinsics(p, name);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("rsibr_splined_" + std::to_string(::getpid()) + ".cameramodel");
  fit.lens.write(file);
  const LensModel back = LensModel::read(file);
  std::filesystem::remove(file);
  EXPECT_EQ(back.name(), name);
  ASSERT_EQ(back.intrinsics().size(), fit.lens.intrinsics().size());
  for (std::size_t k = 0; k < back.intrinsics().size(); ++k)
    EXPECT_NEAR(back.intrinsics()[k], fit.lens.intrinsics()[k], 5e-7);
  double worst = 0;
  for (double fx : {0.05, 0.5, 0.95})
    for (double fy : {0.05, 0.5, 0.95}) {
      const Vec2 q(fx * 639, fy * 479);
      const Vec3 v = back.unproject(q);
      EXPECT_NEAR(v.norm(), 1.0, 1e-9);
      worst = std::max(worst, (back.project(v) - q).norm());
      EXPECT_LT((fit.lens.project(v) - q).norm(), 1e-3);
    }
  EXPECT_LT(worst, 1e-6);
}

// A wide, strongly distorted lens: cross-validation over pinhole, OPENCV4, OPENCV8 and splined picks
// a model whose held-out RMS is the noise level (2-D RMS sigma sqrt 2 = 0.14 px; the pinhole's is
// over 10 times that), and the splined candidate fits too (it is fitted and scored like the others). A pinhole lens: the splined model
// does not win by overfitting; the pinhole does.
TEST(Intrinsics, CrossValidationWithASplinedCandidatePicksAModelThatFits) {
  {
    const IntrinsicsProblem p = board_problem(wide_opencv8_truth(), 10, 0.1, 12);
    std::vector<std::string> models = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8",
                                       splined_candidate(p, 8)};
    int chosen = -1;
    const auto scores = cross_validate_models(p, models, &chosen);
    for (const auto& s : scores)
      std::printf("  wide:    %-60s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px, s.fit_rms_px);
    ASSERT_GE(chosen, 1);
    EXPECT_LT(scores[chosen].held_out_rms_px, 1.1 * 0.1 * std::sqrt(2.0));
    EXPECT_GT(scores[0].held_out_rms_px, 10 * scores[chosen].held_out_rms_px);
    // The splined fit is as close as OPENCV8's (it has more freedom); held out it extrapolates
    // between the halves' coverage, worse than the parametric models but far better than pinhole.
    EXPECT_LT(scores[3].fit_rms_px, 1.01 * scores[2].fit_rms_px);
    EXPECT_LT(scores[3].held_out_rms_px, 2 * 0.1 * std::sqrt(2.0));
  }
  {
    const IntrinsicsProblem p = board_problem(LensModel::pinhole(500, 640, 480), 10, 0.1, 13);
    std::vector<std::string> models = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8",
                                       splined_candidate(p, 8)};
    int chosen = -1;
    const auto scores = cross_validate_models(p, models, &chosen);
    for (const auto& s : scores)
      std::printf("  pinhole: %-60s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px, s.fit_rms_px);
    EXPECT_EQ(models.at(chosen), "LENSMODEL_PINHOLE");
  }
}

// Points across the image, as camera-frame directions of the true lens.
std::vector<Vec3> probe_directions(const LensModel& truth) {
  std::vector<Vec3> v;
  for (double fx : {0.2, 0.5, 0.8})
    for (double fy : {0.2, 0.5, 0.8})
      v.push_back(truth.unproject(Vec2(fx * (truth.width() - 1), fy * (truth.height() - 1))));
  return v;
}

// Known corner noise, several seeds: the fitted lens's projection of a fixed camera-frame direction
// differs from the true lens's by an error whose Mahalanobis distance under the reported 2x2
// covariance is chi-square with 2 degrees of freedom: its mean over 8 seeds x 9 points is 2 (the
// points of one seed are correlated, so the bound is wide: [0.8, 3.5], where a covariance off by a
// factor 2 in sigma would give 0.5 or 8), and no point is beyond chi2_2's 99.99% quantile (18.4).
// The estimated noise sigma is the true one.
TEST(Intrinsics, TrueProjectionsLieWithinTheReportedUncertainty) {
  const double sigma = 0.2;
  const LensModel truth = opencv4_truth();
  for (const std::string model : {"LENSMODEL_OPENCV4", "LENSMODEL_OPENCV8"}) {
    double sum = 0, worst = 0;
    int count = 0;
    for (std::uint64_t seed = 21; seed < 29; ++seed) {
      const IntrinsicsProblem p = board_problem(truth, 10, sigma, seed);
      const IntrinsicsFit fit = fit_intrinsics(p, model);
      EXPECT_NEAR(fit.noise_sigma_px, sigma, 0.1 * sigma);
      for (const Vec3& v : probe_directions(truth)) {
        const Vec2 e = fit.lens.project(v) - truth.project(v);
        const double d2 = e.dot(projection_covariance(fit.lens, fit.intrinsics_covariance, v).inverse() * e);
        ASSERT_TRUE(std::isfinite(d2));
        sum += d2;
        worst = std::max(worst, d2);
        ++count;
      }
    }
    std::printf("  %s: mean Mahalanobis^2 %.3f over %d points, worst %.2f\n", model.c_str(), sum / count, count, worst);
    EXPECT_GT(sum / count, 0.8);
    EXPECT_LT(sum / count, 3.5);
    EXPECT_LT(worst, 18.4);
  }
}

// The splined model: its control points can mimic a small rotation of the camera frame, which only
// mrcal's regularisation pins, so at a fixed camera-frame direction the fitted and true lenses differ
// by a rotation the covariance does not contain (the regularisation rows carry no noise). Up to the
// best rotation (as mrcal compares lenses) every point lies within 3 sigma of the truth.
TEST(Intrinsics, SplinedProjectionsLieWithinTheReportedUncertaintyUpToARotation) {
  const double sigma = 0.2;
  const LensModel truth = opencv4_truth();
  const std::string model = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=80";
  double worst = 0;
  for (std::uint64_t seed = 21; seed < 25; ++seed) {
    const IntrinsicsProblem p = board_problem(truth, 10, sigma, seed);
    const IntrinsicsFit fit = fit_intrinsics(p, model);
    EXPECT_NEAR(fit.noise_sigma_px, sigma, 0.1 * sigma);
    const Mat3 r = best_rotation(truth, fit.lens, p);
    for (const Vec3& v : probe_directions(truth)) {
      const Vec2 e = fit.lens.project(r * v) - truth.project(v);
      const Eigen::Matrix2d c = projection_covariance(fit.lens, fit.intrinsics_covariance, r * v);
      ASSERT_TRUE(c.allFinite());
      const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(c).eigenvalues().maxCoeff();
      ASSERT_GT(largest, 0);
      worst = std::max(worst, e.norm() / std::sqrt(largest));
    }
  }
  std::printf("  splined: worst aligned error %.2f sigma\n", worst);
  EXPECT_LT(worst, 3.0);
}

// The projection uncertainty at the image centre and near a corner shrinks as boards are added:
// from 5 to 20 boards by roughly sqrt(4) = 2 (asserted > 1.5).
TEST(Intrinsics, UncertaintyShrinksAsBoardsAreAdded) {
  const LensModel truth = opencv4_truth();
  const std::vector<Vec3> v = {truth.unproject(Vec2(320, 240)), truth.unproject(Vec2(100, 80))};
  std::vector<double> previous;
  for (int boards : {5, 10, 20}) {
    const IntrinsicsFit fit = fit_intrinsics(board_problem(truth, boards, 0.2, 31), "LENSMODEL_OPENCV4");
    std::vector<double> now;
    for (const Vec3& d : v)
      now.push_back(std::sqrt(projection_covariance(fit.lens, fit.intrinsics_covariance, d).trace()));
    std::printf("  %2d boards: 1-sigma %.4f px at the centre, %.4f px near the corner\n", boards, now[0], now[1]);
    for (std::size_t k = 0; k < now.size(); ++k) {
      EXPECT_GT(now[k], 0);
      if (!previous.empty()) {
        EXPECT_LT(now[k], previous[k]);
      }
    }
    if (boards == 20) {
      const IntrinsicsFit few = fit_intrinsics(board_problem(truth, 5, 0.2, 31), "LENSMODEL_OPENCV4");
      EXPECT_GT(std::sqrt(projection_covariance(few.lens, few.intrinsics_covariance, v[0]).trace()) / now[0], 1.5);
    }
    previous = now;
  }
}

TEST(Intrinsics, BoardCoverageCountsTheCellsHoldingCorners) {
  IntrinsicsProblem p;
  p.width = 400;
  p.height = 200;
  p.boards.push_back({"a", {Vec2(10, 10), Vec2(390, 190), Vec2(12, 15)}});
  EXPECT_DOUBLE_EQ(board_coverage(p, 4, 2), 2.0 / 8);
  p.boards.push_back({"b", {Vec2(150, 50), Vec2(250, 150)}});
  EXPECT_DOUBLE_EQ(board_coverage(p, 4, 2), 4.0 / 8);
  EXPECT_THROW(board_coverage(p, 0, 2), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
