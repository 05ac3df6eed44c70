#include "lights/grey_source_cost.h"

#include "core/parallel.h"
#include "lights/light_source.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace rsibr {

namespace {

constexpr int kChunk = 256;  // texels per partial sum; fixed, so the sums do not depend on the threads

}  // namespace

void grey_texel_residuals(const GreyObservation& t, const std::vector<SourceFrame>& frames, double const* const* x,
                          double delta, double* r, double* J) {
  const std::size_t S = frames.size();
  const std::size_t P = kSourceBlock * S;
  double m[3] = {t.known[0], t.known[1], t.known[2]};
  double w[3];
  for (int c = 0; c < 3; ++c) w[c] = t.sqrt_w * t.inv_scale[c];
  for (std::size_t s = 0; s < S; ++s) {
    const SourceFrame& f = frames[s];
    const double* xs = x[s];
    const Vec3 v = f.d0 + xs[0] * f.t1 + xs[1] * f.t2;
    const double len = v.norm();
    const Vec3 d = v / len;
    const double nd = t.n.dot(d);
    using Dual = ceres::Jet<double, 2>;  // derivatives in (cos theta, rho)
    const Dual k = light_kernels::mean_clamped_cosine(Dual(nd, 0), Dual(xs[5], 1));
    for (int c = 0; c < 3; ++c) m[c] += xs[2 + c] * t.gain[c] * k.a;
    if (!J) continue;
    // n.(dd/du_k) = (n.t_k - (n.d)(d.t_k)) / |v|
    const double dc[2] = {(t.n.dot(f.t1) - nd * d.dot(f.t1)) / len, (t.n.dot(f.t2) - nd * d.dot(f.t2)) / len};
    for (int c = 0; c < 3; ++c) {
      double* row = J + std::size_t(c) * P + kSourceBlock * s;
      const double a = -w[c] * t.gain[c];
      const double p = xs[2 + c];
      row[0] = a * p * k.v[0] * dc[0];
      row[1] = a * p * k.v[0] * dc[1];
      row[2] = row[3] = row[4] = 0;
      row[2 + c] = a * k.a;
      row[5] = a * p * k.v[1];
    }
  }
  for (int c = 0; c < 3; ++c) r[c] = w[c] * (t.obs[c] - m[c]);
  delta *= t.stride;
  const double sq = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  if (!(delta > 0) || sq <= delta * delta) return;
  // Beyond the Huber scale: r' = f r with f = sqrt(rho(s) / s) (the header's derivation).
  const double f = std::sqrt((2 * delta * std::sqrt(sq) - delta * delta) / sq);
  const double g = (delta * delta / (sq * sq) - delta / (sq * std::sqrt(sq))) / (2 * f);
  if (J)
    for (std::size_t k = 0; k < P; ++k) {
      const double q = r[0] * J[k] + r[1] * J[P + k] + r[2] * J[2 * P + k];
      for (int c = 0; c < 3; ++c) J[std::size_t(c) * P + k] = f * J[std::size_t(c) * P + k] + 2 * g * r[c] * q;
    }
  for (int c = 0; c < 3; ++c) r[c] *= f;
}

GreySourceCost::GreySourceCost(std::vector<const GreyObservation*> texels, const std::vector<SourceFrame>* frames,
                               double huber_delta)
    : texels_(std::move(texels)), frames_(frames), delta_(huber_delta) {
  set_num_residuals(kSourceBlock * int(frames->size()) + 1);
  for (std::size_t s = 0; s < frames->size(); ++s) mutable_parameter_block_sizes()->push_back(kSourceBlock);
}

bool GreySourceCost::Evaluate(double const* const* x, double* residuals, double** jacobians) const {
  const int P = kSourceBlock * int(frames_->size());
  const int N = int(texels_.size());
  const int chunks = (N + kChunk - 1) / kChunk;
  if (!jacobians) {
    // The cost only (Ceres trying a step): (0, ..., 0, |r|) has it; no Jacobian is formed.
    std::vector<double> rr(static_cast<std::size_t>(chunks), 0.0);
    parallel_for_rows(chunks, [&](int ch) {
      for (int i = ch * kChunk; i < std::min(N, (ch + 1) * kChunk); ++i) {
        double r[3];
        grey_texel_residuals(*texels_[std::size_t(i)], *frames_, x, delta_, r, nullptr);
        rr[std::size_t(ch)] += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      }
    });
    double sum = 0;
    for (double v : rr) sum += v;
    std::fill(residuals, residuals + P, 0.0);
    residuals[P] = std::sqrt(sum);
    return true;
  }
  // Per chunk: J^T J (upper triangle), J^T r and |r|^2 of its texels' rows.
  struct Partial {
    Eigen::MatrixXd jtj;
    Eigen::VectorXd jtr;
    double rr = 0;
  };
  std::vector<Partial> partial(static_cast<std::size_t>(chunks));
  parallel_for_rows(chunks, [&](int ch) {
    const int begin = ch * kChunk, end = std::min(N, begin + kChunk);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(3 * (end - begin), P);
    Eigen::VectorXd r(3 * (end - begin));
    for (int i = begin; i < end; ++i)
      grey_texel_residuals(*texels_[std::size_t(i)], *frames_, x, delta_, r.data() + 3 * (i - begin),
                           J.data() + std::size_t(3 * (i - begin)) * std::size_t(P));
    Partial& out = partial[std::size_t(ch)];
    out.jtj = Eigen::MatrixXd::Zero(P, P);
    out.jtj.selfadjointView<Eigen::Upper>().rankUpdate(J.transpose());
    out.jtr = J.transpose() * r;
    out.rr = r.squaredNorm();
  });
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(P, P);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(P);
  double rr = 0;
  for (const Partial& p : partial) A += p.jtj, b += p.jtr, rr += p.rr;
  A = A.selfadjointView<Eigen::Upper>();
  // A = J^T J = D^-1 (V L V^T) D^-1 with D the unit-diagonal scaling; R = L^1/2 V^T D^-1.
  Eigen::VectorXd D(P);
  for (int k = 0; k < P; ++k) D(k) = A(k, k) > 0 ? 1 / std::sqrt(A(k, k)) : 0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(D.asDiagonal() * A * D.asDiagonal());
  const Eigen::VectorXd& L = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();
  // Directions of the parameters the texels cannot see (a source of zero power has no direction
  // to see): left out, as a pseudo-inverse would.
  const double floor = P > 0 ? 1e-14 * std::max(L.maxCoeff(), 0.0) * P : 0;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(P, P);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(P);
  const Eigen::VectorXd Db = D.cwiseProduct(b);
  for (int k = 0; k < P; ++k) {
    if (!(L(k) > floor)) continue;
    const double sl = std::sqrt(L(k));
    for (int j = 0; j < P; ++j) R(k, j) = D(j) > 0 ? sl * V(j, k) / D(j) : 0;
    y(k) = V.col(k).dot(Db) / sl;
  }
  for (int k = 0; k < P; ++k) residuals[k] = y(k);
  residuals[P] = std::sqrt(std::max(0.0, rr - y.squaredNorm()));
  for (std::size_t s = 0; s < frames_->size(); ++s) {
    if (!jacobians[s]) continue;
    double* Js = jacobians[s];  // (P + 1) x 6, row-major
    for (int k = 0; k < P; ++k)
      for (int j = 0; j < kSourceBlock; ++j) Js[k * kSourceBlock + j] = R(k, kSourceBlock * int(s) + j);
    for (int j = 0; j < kSourceBlock; ++j) Js[P * kSourceBlock + j] = 0;
  }
  return true;
}

}  // namespace rsibr
