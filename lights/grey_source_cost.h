// The grey-ball texels' residuals against the compact sources (lights/source_recovery.h), as one
// Ceres residual block with its Jacobian written out and evaluated on all cores.
//
// Parameters, per source s, x_s = (u1, u2, P_r, P_g, P_b, rho): the direction as a bounded offset
// in the tangent plane of its region's centroid, d(u) = v / |v| with v = d0 + u1 t1 + u2 t2; the
// power (RGB); the disc's radius. A texel (normal n, albedo gain g = a / pi, per channel weight
// w_c = sqrt(conf) / max(O_c, floor)) has the residuals
//
//   r_c = w_c (O_c - m_c),   m_c = known_c + sum_s P_sc g_c K(n.d_s, rho_s),
//
// so, with K_c and K_rho the partial derivatives of K (lights/light_source.h) in cos theta and rho
// (one dual-number evaluation per source), and dd/du_k = (t_k - d (d.t_k)) / |v|:
//
//   dr_c/dP_sc  = -w_c g_c K
//   dr_c/du_k   = -w_c P_sc g_c K_c n.(dd/du_k)
//   dr_c/drho   = -w_c P_sc g_c K_rho
//
// Robust loss: each texel's three residuals share a Huber loss of scale delta on s = |r|^2,
// rho(s) = s (s <= delta^2), 2 delta sqrt(s) - delta^2 (beyond). One block cannot carry a loss per
// texel, so the block returns r' = sqrt(rho(s) / s) r, whose squared norm is rho(s): the cost is
// the Huber cost exactly, and its gradient (rho'(s) J^T r) is that of a Huber loss per texel, so
// the minimiser is the same. With f = sqrt(rho / s) and |r| > delta,
//
//   dr'/dx = f J + r (df/ds) 2 r^T J,   df/ds = (delta^2 / s^2 - delta / s^1.5) / (2 f),
//
// which is continuous with f = 1, df/ds = 0 at s = delta^2. A texel standing for stride^2 of the
// map's (a sub-grid) has the scale delta * stride: its loss is stride^2 times one map texel's.
//
// The block Ceres sees is compressed. Its Gauss-Newton model at x needs only the cost, J^T J and
// J^T r, so with J^T J = R^T R (R square, from the eigen-decomposition of J^T J scaled to a unit
// diagonal; directions it cannot see dropped) the block returns the P + 1 residuals
// (R^-T J^T r, sqrt(|r|^2 - |R^-T J^T r|^2)) and the Jacobian (R; 0): the same cost, gradient and
// J^T J as the 3N rows, for any N. (That is a thin QR of J, J = Q R, without Q.) Asked for no
// Jacobian (Ceres costing a trial step), it returns (0, ..., 0, |r|): the cost, without forming
// J. The rows are evaluated on all cores and summed in a fixed order of chunks, so the result does
// not depend on the threads.
//
// Why not Ceres' automatic differentiation, one block per texel: with S sources it evaluates every
// source's K in 6-wide dual numbers once per 6-parameter block (S^2 kernels per texel), and
// Ceres' bookkeeping per block and per Jacobian entry (validity checks, copies, the manifold's
// product) cost more than the texel's model.
#pragma once

#include "core/vec.h"

#include <ceres/ceres.h>

#include <vector>

namespace rsibr {

// Parameters per source: u1, u2 (the direction's offset), P (RGB), rho.
inline constexpr int kSourceBlock = 6;

// A source's direction frame: d(u) = normalize(d0 + u1 t1 + u2 t2), |u_k| <= bound = tan(region
// radius); max_radius bounds rho.
struct SourceFrame {
  Vec3 d0, t1, t2;
  double bound = 0, max_radius = 0;
};

template <typename T>
void source_direction(const SourceFrame& f, const T* x, T* d) {
  T len2(0);
  for (int k = 0; k < 3; ++k) {
    d[k] = T(f.d0[k]) + x[0] * T(f.t1[k]) + x[1] * T(f.t2[k]);
    len2 += d[k] * d[k];
  }
  using std::sqrt;
  const T len = sqrt(len2);
  for (int k = 0; k < 3; ++k) d[k] /= len;
}

inline Vec3 source_direction(const SourceFrame& f, const double* x) {
  double d[3];
  source_direction(f, x, d);
  return Vec3(d[0], d[1], d[2]);
}

// What the grey-ball residuals of one texel need.
struct GreyObservation {
  Vec3 n;          // world normal, unit
  Vec3 obs;        // captured value O
  Vec3 known;      // the known part's prediction
  Vec3 gain;       // albedo / pi
  Vec3 inv_scale;  // 1 / max(O, floor)
  double sqrt_w = 1;
  // A texel of a sub-grid standing for stride^2 of the map's (sqrt_w includes the factor stride):
  // its Huber scale is delta * stride, so its loss is stride^2 times that of one map texel.
  double stride = 1;
};

// One texel's three residuals r' at x (one block of 6 per frame) and, when J is not null, their
// Jacobian, row-major 3 x 6 S. huber_delta <= 0: plain least squares.
void grey_texel_residuals(const GreyObservation& t, const std::vector<SourceFrame>& frames, double const* const* x,
                          double huber_delta, double* r, double* J);

// The texels' compressed block: 6 S + 1 residuals, one parameter block of 6 per frame. The texels
// and frames are not owned and must outlive it.
class GreySourceCost final : public ceres::CostFunction {
 public:
  GreySourceCost(std::vector<const GreyObservation*> texels, const std::vector<SourceFrame>* frames,
                 double huber_delta);
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override;

 private:
  std::vector<const GreyObservation*> texels_;
  const std::vector<SourceFrame>* frames_;
  double delta_;
};

}  // namespace rsibr
