// Intrinsic calibration from chessboard images: mrgingham finds the corners, OpenCV's
// calibrateCamera (distortion held at zero) seeds a pinhole core and the board poses, and
// mrcal_optimize solves in two stages as mrcal's own calibration tool does: (1) the core and the
// board poses with the distortions at zero, no regularisation; (2) everything, with mrcal's
// regularisation and outlier rejection. The lens model is chosen by cross-validation: each model
// is fitted to one half of the boards and scored by the reprojection RMS of the other half (board
// poses refitted with the intrinsics held), both ways round; the simplest model within 5% of the
// best held-out RMS wins.
//
// Splined models (LENSMODEL_SPLINED_STEREOGRAPHIC_...) are staged as mrcal-calibrate-cameras does:
// a LENSMODEL_STEREOGRAPHIC core and the board poses first, then the spline's control points from
// zero (the splined model with zero control points is the stereographic one) and everything with
// regularisation. splined_candidate() names a spline that covers the seed's field of view.
//
// Uncertainty (intrinsics_covariance): at the optimum, mrcal's Jacobian J (observations and
// regularisation rows) gives the covariance of the whole state b for per-axis corner noise s:
//   db = -(J^T J)^-1 J_obs^T dq  =>  Var(b) = s^2 (J^T J)^-1 (J_obs^T J_obs) (J^T J)^-1
// (mrcal's formula: the regularisation rows carry no noise). The intrinsics block of Var(b) is
// the intrinsics' covariance with the board poses marginalised. s^2 is estimated from the
// residuals: sum of squared inlier residuals / (inlier measurements - states).
//
// Board frame (mrcal's): corner (i, j) (i along x, 0..corners_x-1; j along y) at (i s, j s, 0);
// corners are listed row-major (j outer, i inner), as mrgingham writes them.
#pragma once

#include "core/lens_model.h"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct ChessboardObservation {
  std::string name;           // file name, for errors
  std::vector<Vec2> corners;  // pixels, row-major, corners_x * corners_y
};

struct IntrinsicsProblem {
  int width = 0, height = 0;         // image size
  int corners_x = 0, corners_y = 0;  // inner corners
  double spacing_m = 0;
  std::vector<ChessboardObservation> boards;
};

struct IntrinsicsFit {
  LensModel lens = LensModel::pinhole(1, 1, 1);
  double rms_px = 0;                                // over the corners not rejected as outliers
  int outliers = 0;                                 // corners rejected by mrcal
  std::vector<std::array<double, 6>> rt_cam_board;  // per board: Rodrigues rotation, translation (m)
  std::vector<Vec2> residuals;                      // observed - projected, every corner of every board, in board order
  // Covariance of lens.intrinsics() (mrcal's order), board poses marginalised; px^2 per unit^2.
  Eigen::MatrixXd intrinsics_covariance;
  double noise_sigma_px = 0;  // per-axis corner noise estimated from the residuals
};

// The 2x2 covariance (px^2) of the projection of a fixed camera-frame point v, propagated from the
// intrinsics covariance: Var(q) = G C G^T, G = dq/dintrinsics at v (mrcal_project's gradient).
// Unlike mrcal's projection_uncertainty this holds v fixed in the camera frame; mrcal instead
// fixes the point relative to the observed boards and lets the camera frame move with the
// solution (the reference-frame shift), which removes the part of the principal-point uncertainty
// that a small rotation of the whole camera frame would absorb. Ours is therefore the larger
// (conservative) number, and it is the right one for comparing a fitted lens with a true one at
// the same camera-frame direction, as the tests do.
Eigen::Matrix2d projection_covariance(const LensModel& lens, const Eigen::MatrixXd& intrinsics_covariance,
                                      const Vec3& cam);

// The splined candidate for a problem: "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=<nx>_Ny=<ny>_fov_x_deg=<f>"
// with Ny = round(nx * height / width) and f the pinhole seed's horizontal field of view plus 15%,
// rounded up to a whole degree (the spline's knots must span the image).
std::string splined_candidate(const IntrinsicsProblem& problem, int nx = 10);

// Fraction of the cells of a cells_x x cells_y grid over the image that hold at least one corner.
double board_coverage(const IntrinsicsProblem& problem, int cells_x, int cells_y);

// Fits `model` (an mrcal model name with a core: LENSMODEL_PINHOLE, _OPENCV4/5/8/12, _STEREOGRAPHIC,
// _SPLINED_STEREOGRAPHIC_...) to the boards
// listed in `subset` (all when empty). Throws std::invalid_argument for fewer than 3 boards, corner
// lists of the wrong length or an unknown model; std::runtime_error when the solve fails.
IntrinsicsFit fit_intrinsics(const IntrinsicsProblem& problem, const std::string& model,
                             const std::vector<int>& subset = {});

// Reprojection RMS of the boards in `subset` under a fixed lens (each board's pose fitted alone).
double held_out_rms(const IntrinsicsProblem& problem, const LensModel& lens, const std::vector<int>& subset);

struct ModelScore {
  std::string model;
  double held_out_rms_px = 0;  // mean of the two halves' held-out RMS
  double fit_rms_px = 0;       // fitted to all boards
};

// Scores every model by two-fold cross-validation (boards alternately in the halves); returns the
// scores in the given order and sets *chosen to the index of the simplest model (earliest in
// `models`, which should be listed simplest first) within 5% of the best held-out RMS.
std::vector<ModelScore> cross_validate_models(const IntrinsicsProblem& problem, const std::vector<std::string>& models,
                                              int* chosen);

// mrgingham on an 8-bit grey image: the gridn x gridn inner corners, row-major, or nullopt.
std::optional<std::vector<Vec2>> find_chessboard(const cv::Mat& gray8, int gridn);

}  // namespace rsibr
