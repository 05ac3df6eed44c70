#include "calib/lens/intrinsics.h"

#include "core/lazy_library.h"

// mrcal's C header has no extern "C" guard of its own.
extern "C" {
#include <mrcal/mrcal.h>
// _mrcal_num_j_nonzero: the Jacobian's size, to allocate it for mrcal_optimizer_callback.
#include <mrcal/mrcal-internal.h>
}
#include <suitesparse/cholmod.h>
#include <mrgingham/mrgingham.hh>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <type_traits>

namespace rsibr {

namespace {

std::vector<cv::Point3f> board_points(const IntrinsicsProblem& p) {
  std::vector<cv::Point3f> pts;
  for (int j = 0; j < p.corners_y; ++j)
    for (int i = 0; i < p.corners_x; ++i)
      pts.emplace_back(static_cast<float>(i * p.spacing_m), static_cast<float>(j * p.spacing_m), 0.f);
  return pts;
}

std::vector<cv::Point2f> image_points(const ChessboardObservation& b) {
  std::vector<cv::Point2f> pts;
  for (const Vec2& c : b.corners) pts.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
  return pts;
}

void check(const IntrinsicsProblem& p, const std::vector<int>& subset) {
  if (p.width <= 0 || p.height <= 0) throw std::invalid_argument("intrinsics: the image size must be positive");
  if (p.corners_x < 2 || p.corners_y < 2 || !(p.spacing_m > 0))
    throw std::invalid_argument("intrinsics: a board needs >= 2 x 2 inner corners and a positive spacing");
  if (subset.size() < 3)
    throw std::invalid_argument("intrinsics: " + std::to_string(subset.size()) + " chessboards, need at least 3");
  for (int i : subset)
    if (p.boards.at(i).corners.size() != static_cast<std::size_t>(p.corners_x * p.corners_y))
      throw std::invalid_argument(p.boards[i].name + ": " + std::to_string(p.boards[i].corners.size()) +
                                  " corners, expected " + std::to_string(p.corners_x * p.corners_y));
}

mrcal_lensmodel_t lensmodel(const std::string& name) {
  LensModel::check_name(name);  // splines mrcal would assert on
  mrcal_lensmodel_t m;
  if (!mrcal_lensmodel_from_name(&m, name.c_str()) || !mrcal_lensmodel_type_is_valid(m.type))
    throw std::invalid_argument("intrinsics: unknown lens model '" + name + "'");
  const mrcal_lensmodel_metadata_t meta = mrcal_lensmodel_metadata(&m);
  if (!meta.has_core) throw std::invalid_argument("intrinsics: model '" + name + "' has no intrinsics core");
  return m;
}

Mat3 rotation(const std::array<double, 6>& rt) {
  const Vec3 r(rt[0], rt[1], rt[2]);
  const double a = r.norm();
  return a > 0 ? Mat3(Eigen::AngleAxisd(a, r / a)) : Mat3::Identity();
}

// The problem's layout as mrcal sees it: board k seen by the one camera (at the reference, no
// extrinsics) as frame k; point ranges mrcal needs only for its point observations (none here).
std::vector<mrcal_observation_board_t> board_observations(int n) {
  std::vector<mrcal_observation_board_t> obs(n);
  for (int k = 0; k < n; ++k) {
    obs[k].icam.intrinsics = 0;
    obs[k].icam.extrinsics = -1;
    obs[k].iframe = k;
  }
  return obs;
}

mrcal_problem_constants_t problem_constants() {
  mrcal_problem_constants_t constants{};
  constants.point_min_range = 1e-3;
  constants.point_max_range = 1e4;
  return constants;
}

// One mrcal_optimize call over the boards of `subset` with one camera at the reference.
mrcal_stats_t optimize(const IntrinsicsProblem& p, const std::vector<int>& subset, const mrcal_lensmodel_t& model,
                       std::vector<double>& intrinsics, std::vector<mrcal_pose_t>& frames,
                       std::vector<mrcal_point3_t>& pool, mrcal_problem_selections_t sel) {
  const int n = static_cast<int>(subset.size());
  std::vector<mrcal_observation_board_t> obs = board_observations(n);
  const int sizes[2] = {p.width, p.height};
  const mrcal_problem_constants_t constants = problem_constants();
  return mrcal_optimize(nullptr, 0, nullptr, 0, intrinsics.data(), nullptr, frames.data(), nullptr, nullptr, 1, 0, n, 0,
                        0, obs.data(), nullptr, n, 0, pool.data(), &model, sizes, sel, &constants, p.spacing_m,
                        p.corners_x, p.corners_y, false, false);
}

std::vector<mrcal_point3_t> observation_pool(const IntrinsicsProblem& p, const std::vector<int>& subset) {
  std::vector<mrcal_point3_t> pool;
  for (int i : subset)
    for (const Vec2& c : p.boards[i].corners) {
      mrcal_point3_t q;
      q.x = c.x();
      q.y = c.y();
      q.z = 1.0;
      pool.push_back(q);
    }
  return pool;
}

// The covariance of the intrinsics at the optimum of one mrcal problem (formula in intrinsics.h).
// mrcal's Jacobian is in its packed (unitless) state b_p = b / d; Var(b) = D Var(b_p) D, D = diag(d).
Eigen::MatrixXd covariance(const IntrinsicsProblem& p, int n, const mrcal_lensmodel_t& model,
                           const std::vector<double>& intrinsics, const std::vector<mrcal_pose_t>& frames,
                           const std::vector<mrcal_point3_t>& pool, mrcal_problem_selections_t sel, double* sigma) {
  std::vector<mrcal_observation_board_t> obs = board_observations(n);
  const int sizes[2] = {p.width, p.height};
  const mrcal_problem_constants_t constants = problem_constants();
  const int nstate = mrcal_num_states(1, 0, n, 0, 0, n, sel, &model);
  const int nmeas = mrcal_num_measurements(n, 0, p.corners_x, p.corners_y, 1, 0, n, 0, 0, sel, &model);
  const int nboard = mrcal_num_measurements_boards(n, p.corners_x, p.corners_y);
  const int nnz = _mrcal_num_j_nonzero(n, 0, p.corners_x, p.corners_y, 1, 0, n, 0, 0, obs.data(), nullptr, sel, &model);
  cholmod_common common;
  cholmod_start(&common);
  cholmod_sparse* jt = cholmod_allocate_sparse(nstate, nmeas, nnz, 1, 1, 0, CHOLMOD_REAL, &common);
  std::vector<double> b(nstate), x(nmeas);
  const bool ok =
      jt && mrcal_optimizer_callback(b.data(), nstate * int(sizeof(double)), x.data(), nmeas * int(sizeof(double)), jt,
                                     intrinsics.data(), nullptr, frames.data(), nullptr, nullptr, 1, 0, n, 0, 0,
                                     obs.data(), nullptr, n, 0, pool.data(), &model, sizes, sel, &constants,
                                     p.spacing_m, p.corners_x, p.corners_y, false);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(nmeas, nstate);
  if (ok) {
    // Jt is compressed by column: column r holds row r of J.
    const int* cp = static_cast<const int*>(jt->p);
    const int* ri = static_cast<const int*>(jt->i);
    const double* v = static_cast<const double*>(jt->x);
    for (int r = 0; r < nmeas; ++r)
      for (int k = cp[r]; k < cp[r + 1]; ++k) j(r, ri[k]) = v[k];
  }
  if (jt) cholmod_free_sparse(&jt, &common);
  cholmod_finish(&common);
  if (!ok) throw std::runtime_error("intrinsics: mrcal_optimizer_callback failed");

  int inliers = 0;
  for (const mrcal_point3_t& q : pool) inliers += q.z >= 0;
  double sum2 = 0;
  for (int r = 0; r < nboard; ++r) sum2 += x[r] * x[r];
  const int dof = 2 * inliers - nstate;
  const double s2 = dof > 0 ? sum2 / dof : 0.0;
  if (sigma) *sigma = std::sqrt(s2);

  const Eigen::MatrixXd jtj = j.transpose() * j;
  const Eigen::MatrixXd jo = j.topRows(nboard);
  const Eigen::MatrixXd m = jo.transpose() * jo;
  // Pseudo-inverse through the symmetric eigen-decomposition: a direction the data and the
  // regularisation leave free (none in a well-posed problem) gets no variance rather than NaN.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jtj);
  const Eigen::VectorXd ev = eig.eigenvalues();
  Eigen::VectorXd inv(ev.size());
  for (int k = 0; k < ev.size(); ++k) inv[k] = ev[k] > 1e-12 * ev.maxCoeff() ? 1.0 / ev[k] : 0.0;
  const Eigen::MatrixXd a = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(nstate);
  mrcal_unpack_solver_state_vector(d.data(), 1, 0, n, 0, 0, sel, &model);
  const Eigen::MatrixXd cov = s2 * d.asDiagonal() * (a * m * a) * d.asDiagonal();
  const int i0 = mrcal_state_index_intrinsics(0, 1, 0, n, 0, 0, n, sel, &model);
  const int ni = mrcal_num_states_intrinsics(1, sel, &model);
  return cov.block(i0, i0, ni, ni);
}

std::vector<int> all_boards(const IntrinsicsProblem& p) {
  std::vector<int> s(p.boards.size());
  std::iota(s.begin(), s.end(), 0);
  return s;
}

// Residuals observed - projected of one board under a lens and a pose.
void board_residuals(const IntrinsicsProblem& p, int board, const LensModel& lens, const std::array<double, 6>& rt,
                     std::vector<Vec2>& out) {
  const Mat3 r = rotation(rt);
  const Vec3 t(rt[3], rt[4], rt[5]);
  int k = 0;
  for (int j = 0; j < p.corners_y; ++j)
    for (int i = 0; i < p.corners_x; ++i, ++k)
      out.push_back(p.boards[board].corners[k] - lens.project(r * Vec3(i * p.spacing_m, j * p.spacing_m, 0) + t));
}

// OpenCV's planar calibration of `subset` with the distortion held at zero: a pinhole core and each
// board's pose, the seed of every mrcal solve.
struct PinholeSeed {
  cv::Mat k;                          // 3x3 CV_64F
  std::vector<cv::Mat> rvecs, tvecs;  // board -> camera, one per subset entry
};
PinholeSeed pinhole_seed(const IntrinsicsProblem& p, const std::vector<int>& subset) {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (int i : subset) {
    object.push_back(board_points(p));
    image.push_back(image_points(p.boards[i]));
  }
  PinholeSeed seed;
  cv::Mat dist;
  cv::calibrateCamera(object, image, cv::Size(p.width, p.height), seed.k, dist, seed.rvecs, seed.tvecs,
                      cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST);
  return seed;
}

}  // namespace

IntrinsicsFit fit_intrinsics(const IntrinsicsProblem& p, const std::string& model_name,
                             const std::vector<int>& subset_in) {
  const std::vector<int> subset = subset_in.empty() ? all_boards(p) : subset_in;
  check(p, subset);
  const mrcal_lensmodel_t model = lensmodel(model_name);
  const int nparams = mrcal_lensmodel_num_params(&model);

  const PinholeSeed seed = pinhole_seed(p, subset);
  const cv::Mat& k = seed.k;
  std::vector<double> intrinsics(nparams, 0.0);
  intrinsics[0] = k.at<double>(0, 0);
  intrinsics[1] = k.at<double>(1, 1);
  intrinsics[2] = k.at<double>(0, 2);
  intrinsics[3] = k.at<double>(1, 2);
  std::vector<mrcal_pose_t> frames(subset.size());
  for (std::size_t b = 0; b < subset.size(); ++b)
    for (int c = 0; c < 3; ++c) {
      frames[b].r.xyz[c] = seed.rvecs[b].at<double>(c);
      frames[b].t.xyz[c] = seed.tvecs[b].at<double>(c);
    }
  std::vector<mrcal_point3_t> pool = observation_pool(p, subset);

  // Stage 1: core and poses, distortions at zero; stage 2: everything, regularised, outliers out.
  // A splined model's stage 1 is a LENSMODEL_STEREOGRAPHIC solve (its zero-spline equivalent).
  mrcal_problem_selections_t sel{};
  sel.do_optimize_intrinsics_core = true;
  sel.do_optimize_frames = true;
  if (model.type == MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC) {
    mrcal_lensmodel_t stereographic{};
    stereographic.type = MRCAL_LENSMODEL_STEREOGRAPHIC;
    std::vector<double> core(intrinsics.begin(), intrinsics.begin() + 4);
    optimize(p, subset, stereographic, core, frames, pool, sel);
    std::copy(core.begin(), core.end(), intrinsics.begin());
  } else {
    optimize(p, subset, model, intrinsics, frames, pool, sel);
  }
  sel.do_optimize_intrinsics_distortions = true;
  sel.do_apply_regularization = true;
  sel.do_apply_outlier_rejection = true;
  const mrcal_stats_t stats = optimize(p, subset, model, intrinsics, frames, pool, sel);
  if (!std::isfinite(stats.rms_reproj_error__pixels) || stats.rms_reproj_error__pixels < 0)
    throw std::runtime_error("intrinsics: mrcal_optimize failed for " + model_name);
  for (double v : intrinsics)
    if (!std::isfinite(v)) throw std::runtime_error("intrinsics: mrcal_optimize diverged for " + model_name);

  IntrinsicsFit fit;
  fit.lens = LensModel(model_name, intrinsics, p.width, p.height);
  fit.outliers = stats.Noutliers;
  double sum2 = 0;
  int used = 0;
  for (std::size_t b = 0; b < subset.size(); ++b) {
    std::array<double, 6> rt{};
    for (int c = 0; c < 3; ++c) rt[c] = frames[b].r.xyz[c], rt[3 + c] = frames[b].t.xyz[c];
    fit.rt_cam_board.push_back(rt);
    const std::size_t first = fit.residuals.size();
    board_residuals(p, subset[b], fit.lens, rt, fit.residuals);
    for (std::size_t q = first; q < fit.residuals.size(); ++q)
      if (pool[q].z >= 0) sum2 += fit.residuals[q].squaredNorm(), ++used;
  }
  fit.rms_px = used > 0 ? std::sqrt(sum2 / used) : 0.0;
  fit.intrinsics_covariance =
      covariance(p, static_cast<int>(subset.size()), model, intrinsics, frames, pool, sel, &fit.noise_sigma_px);
  if (!fit.intrinsics_covariance.allFinite())
    throw std::runtime_error("intrinsics: the covariance of " + model_name + " is not finite");
  return fit;
}

Eigen::Matrix2d projection_covariance(const LensModel& lens, const Eigen::MatrixXd& c, const Vec3& cam) {
  const mrcal_lensmodel_t model = lensmodel(lens.name());
  const int ni = static_cast<int>(lens.intrinsics().size());
  if (c.rows() != ni || c.cols() != ni)
    throw std::invalid_argument("projection_covariance: a " + std::to_string(c.rows()) + "x" +
                                std::to_string(c.cols()) + " covariance for " + std::to_string(ni) + " intrinsics");
  mrcal_point3_t v;
  v.x = cam.x();
  v.y = cam.y();
  v.z = cam.z();
  mrcal_point2_t q;
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> g(2, ni);
  if (!mrcal_project(&q, nullptr, g.data(), &v, 1, &model, lens.intrinsics().data()))
    throw std::runtime_error(lens.name() + ": mrcal_project failed");
  return g * c * g.transpose();
}

std::string splined_candidate(const IntrinsicsProblem& p, int nx) {
  if (nx < 4) throw std::invalid_argument("splined_candidate: Nx must be >= 4");
  const std::vector<int> all = all_boards(p);
  check(p, all);
  const cv::Mat k = pinhole_seed(p, all).k;
  const double fx = k.at<double>(0, 0), cx = k.at<double>(0, 2);
  const double half = std::max(cx + 0.5, p.width - 0.5 - cx);
  const double fov = std::ceil(1.15 * 2 * std::atan(half / fx) * 180 / M_PI);
  const int ny = std::max(3, static_cast<int>(std::lround(nx * double(p.height) / p.width)));
  return "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=" + std::to_string(nx) + "_Ny=" + std::to_string(ny) +
         "_fov_x_deg=" + std::to_string(static_cast<int>(std::min(fov, 179.0)));
}

double board_coverage(const IntrinsicsProblem& p, int cells_x, int cells_y) {
  if (cells_x < 1 || cells_y < 1 || p.width <= 0 || p.height <= 0)
    throw std::invalid_argument("board_coverage: needs a positive grid and image size");
  std::vector<char> hit(cells_x * cells_y, 0);
  for (const auto& b : p.boards)
    for (const Vec2& q : b.corners) {
      const int cx = std::clamp(static_cast<int>((q.x() + 0.5) / p.width * cells_x), 0, cells_x - 1);
      const int cy = std::clamp(static_cast<int>((q.y() + 0.5) / p.height * cells_y), 0, cells_y - 1);
      hit[cy * cells_x + cx] = 1;
    }
  return double(std::count(hit.begin(), hit.end(), 1)) / hit.size();
}

double held_out_rms(const IntrinsicsProblem& p, const LensModel& lens, const std::vector<int>& subset) {
  if (subset.empty()) throw std::invalid_argument("intrinsics: no held-out boards");
  const mrcal_lensmodel_t model = lensmodel(lens.name());
  std::vector<double> intrinsics = lens.intrinsics();
  const auto& in = lens.intrinsics();
  const cv::Matx33d k(in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1);
  std::vector<mrcal_pose_t> frames(subset.size());
  for (std::size_t b = 0; b < subset.size(); ++b) {
    cv::Vec3d r, t;
    cv::solvePnP(board_points(p), image_points(p.boards.at(subset[b])), k, cv::noArray(), r, t);
    for (int c = 0; c < 3; ++c) frames[b].r.xyz[c] = r[c], frames[b].t.xyz[c] = t[c];
  }
  std::vector<mrcal_point3_t> pool = observation_pool(p, subset);
  mrcal_problem_selections_t sel{};
  sel.do_optimize_frames = true;
  optimize(p, subset, model, intrinsics, frames, pool, sel);
  std::vector<Vec2> res;
  for (std::size_t b = 0; b < subset.size(); ++b) {
    std::array<double, 6> rt{};
    for (int c = 0; c < 3; ++c) rt[c] = frames[b].r.xyz[c], rt[3 + c] = frames[b].t.xyz[c];
    board_residuals(p, subset[b], lens, rt, res);
  }
  double sum2 = 0;
  for (const Vec2& r : res) sum2 += r.squaredNorm();
  return std::sqrt(sum2 / res.size());
}

std::vector<ModelScore> cross_validate_models(const IntrinsicsProblem& p, const std::vector<std::string>& models,
                                              int* chosen) {
  std::vector<int> a, b;
  for (int i = 0; i < static_cast<int>(p.boards.size()); ++i) (i % 2 ? b : a).push_back(i);
  std::vector<ModelScore> scores;
  for (const std::string& m : models) {
    ModelScore s;
    s.model = m;
    s.held_out_rms_px =
        0.5 * (held_out_rms(p, fit_intrinsics(p, m, a).lens, b) + held_out_rms(p, fit_intrinsics(p, m, b).lens, a));
    s.fit_rms_px = fit_intrinsics(p, m).rms_px;
    scores.push_back(s);
  }
  double best = 1e300;
  for (const ModelScore& s : scores) best = std::min(best, s.held_out_rms_px);
  if (chosen) {
    *chosen = 0;
    for (int i = 0; i < static_cast<int>(scores.size()); ++i)
      if (scores[i].held_out_rms_px <= 1.05 * best) {
        *chosen = i;
        break;
      }
  }
  return scores;
}

std::optional<std::vector<Vec2>> find_chessboard(const cv::Mat& gray8, int gridn) {
  if (gray8.type() != CV_8UC1) throw std::invalid_argument("find_chessboard: expected an 8-bit grey image");
  // Contrast-limited histogram equalisation (clip 8) and a 3x3 box blur first, as the mrgingham tool
  // prepares images (without the blur the library misses clean, sharp renders).
  cv::Mat equalised;
  cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE();
  clahe->setClipLimit(8);
  clahe->apply(gray8, equalised);
  cv::blur(equalised, equalised, cv::Size(3, 3));
  // mrgingham is opened on first use (core/lazy_library.h); the signature is checked against its header.
  using FindFn = int (*)(std::vector<mrgingham::PointDouble>&, signed char**, int, const cv::Mat&, int, bool,
                         mrgingham::debug_sequence_t, const char*);
  static_assert(std::is_same_v<decltype(static_cast<FindFn>(&mrgingham::find_chessboard_from_image_array)), FindFn>);
  static const LazyLibrary library(RSIBR_MRGINGHAM_SONAME, "finding chessboard corners");
  static const auto find = library.function<FindFn>(
      "_ZN9mrgingham32find_chessboard_from_image_arrayERSt6vectorINS_11PointDoubleESaIS1_EEPPaiRKN2cv3MatEibNS_16debug_"
      "sequence_tEPKc");
  std::vector<mrgingham::PointDouble> pts;
  signed char* levels = nullptr;
  const int level = find(pts, &levels, gridn, equalised, -1, false, mrgingham::debug_sequence_t(), nullptr);
  std::free(levels);
  if (level < 0 || pts.size() != static_cast<std::size_t>(gridn * gridn)) return std::nullopt;
  std::vector<Vec2> out;
  for (const auto& q : pts) out.emplace_back(q.x, q.y);
  return out;
}

}  // namespace rsibr
