// Non-negative least squares in Gram form (Lawson & Hanson, "Solving Least Squares Problems",
// ch. 23): minimise 1/2 x^T Q x - p^T x subject to x >= 0, with Q = A^T A (symmetric positive
// semi-definite) and p = A^T b. Deterministic; used for the monotone Debevec solve.
#pragma once

#include <Eigen/Core>

namespace rsibr {

// Returns x >= 0 at the constrained minimum (within `tolerance` on the gradient). Throws
// std::invalid_argument on mismatched sizes.
Eigen::VectorXd nnls_gram(const Eigen::MatrixXd& Q, const Eigen::VectorXd& p, double tolerance = 1e-10,
                          int max_iterations = 0);

}  // namespace rsibr
