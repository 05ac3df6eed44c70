#include "hdr/nnls.h"

#include <Eigen/Cholesky>

#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

// Solves Q_PP z_P = p_P on the passive set P (LDLT: Q_PP may be only semi-definite).
Eigen::VectorXd solve_passive(const Eigen::MatrixXd& Q, const Eigen::VectorXd& p, const std::vector<bool>& passive) {
  std::vector<int> idx;
  for (int i = 0; i < int(passive.size()); ++i)
    if (passive[std::size_t(i)]) idx.push_back(i);
  const int m = int(idx.size());
  Eigen::MatrixXd Qp(m, m);
  Eigen::VectorXd pp(m);
  for (int a = 0; a < m; ++a) {
    pp(a) = p(idx[std::size_t(a)]);
    for (int b = 0; b < m; ++b) Qp(a, b) = Q(idx[std::size_t(a)], idx[std::size_t(b)]);
  }
  const Eigen::VectorXd zp = Qp.ldlt().solve(pp);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(p.size());
  for (int a = 0; a < m; ++a) z(idx[std::size_t(a)]) = zp(a);
  return z;
}

}  // namespace

Eigen::VectorXd nnls_gram(const Eigen::MatrixXd& Q, const Eigen::VectorXd& p, double tolerance, int max_iterations) {
  const int n = int(p.size());
  if (Q.rows() != n || Q.cols() != n) throw std::invalid_argument("nnls_gram: Q must be n x n with n = p.size()");
  if (max_iterations <= 0) max_iterations = 3 * n + 10;
  // When the unconstrained minimum is feasible it is the answer (Q positive definite); the active
  // set iterations are for when it is not.
  {
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Q);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive()) {
      const Eigen::VectorXd z = ldlt.solve(p);
      if (z.allFinite() && (z.array() >= 0).all() && (Q * z - p).norm() <= 1e-9 * (1 + p.norm())) return z;
    }
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(std::size_t(n), false);
  for (int outer = 0; outer < max_iterations; ++outer) {
    const Eigen::VectorXd w = p - Q * x;  // negative gradient
    int best = -1;
    double best_w = tolerance;
    for (int i = 0; i < n; ++i)
      if (!passive[std::size_t(i)] && w(i) > best_w) best_w = w(i), best = i;
    if (best < 0) break;
    passive[std::size_t(best)] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      const Eigen::VectorXd z = solve_passive(Q, p, passive);
      bool feasible = true;
      for (int i = 0; i < n; ++i)
        if (passive[std::size_t(i)] && z(i) <= 0) feasible = false;
      if (feasible) {
        x = z;
        break;
      }
      // Step from x toward z as far as feasibility allows; drop the variables that hit zero.
      double alpha = 1.0;
      for (int i = 0; i < n; ++i)
        if (passive[std::size_t(i)] && z(i) <= 0) alpha = std::min(alpha, x(i) / (x(i) - z(i)));
      x += alpha * (z - x);
      for (int i = 0; i < n; ++i)
        if (passive[std::size_t(i)] && x(i) <= 1e-15) passive[std::size_t(i)] = false, x(i) = 0;
    }
  }
  return x;
}

}  // namespace rsibr
