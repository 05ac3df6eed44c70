// calib/intrinsics.h: mrcal's solve recovers a known lens from noisy corners of boards posed by
// capture/chessboard.h; cross-validation picks the true model family; mrgingham finds the corners.
#include "calib/intrinsics.h"

#include "capture/chessboard.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

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
    for (const auto& s : scores) std::printf("  distorted: %-20s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px, s.fit_rms_px);
    EXPECT_EQ(models.at(chosen), "LENSMODEL_OPENCV4");
    EXPECT_GT(scores[0].held_out_rms_px, 3 * scores[1].held_out_rms_px);
  }
  {
    const IntrinsicsProblem p = board_problem(LensModel::pinhole(500, 640, 480), 12, 0.1, 6);
    int chosen = -1;
    const auto scores = cross_validate_models(p, models, &chosen);
    for (const auto& s : scores) std::printf("  pinhole:   %-20s held-out %.4f px, fit %.4f px\n", s.model.c_str(), s.held_out_rms_px, s.fit_rms_px);
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

}  // namespace
}  // namespace rsibr
