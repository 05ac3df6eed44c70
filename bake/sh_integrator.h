// Irradiance from order-2 spherical harmonics (Ramamoorthi & Hanrahan 2001, "An efficient
// representation for irradiance environment maps"), Lambert only:
//
//   L_lm = sum_q L(q) Y_lm(w_q) Omega(q)                  (9 coefficients per channel, exact
//                                                          texel solid angles, any layout)
//   E(n) = sum_{l<=2} A_l sum_m L_lm Y_lm(n),   A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4
//   L_o  = rho / pi * max(0, E(n))
//
// Exact for environments with no energy above l = 2; otherwise the truncation error of the
// clamped cosine (about 1% average for natural lighting, R&H; much more for a sun, see
// tests/bake/integrator_test.cpp). Throws std::invalid_argument for a BRDF that is not
// LambertBrdf. Deterministic; no quality knob (the order is fixed).
#pragma once

#include "bake/integrator.h"

#include <array>

namespace rsibr {

class ShIntegrator final : public Integrator {
 public:
  explicit ShIntegrator(const EnvMap& env);
  std::string name() const override { return "sh"; }
  cv::Mat radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                       const IntegratorOptions& options, const std::function<void(int)>& progress = {}) const override;

  // The 9 real SH basis functions at a unit direction (order: l=0; l=1: y, z, x; l=2: xy, yz,
  // 3z^2-1, xz, x^2-y^2 with R&H's constants).
  static std::array<double, 9> basis(const Vec3& d);
  // Irradiance E(n) (RGB) at a unit world normal, clamped at 0 (order 2 rings negative on the
  // side opposite a sun).
  Vec3 irradiance(const Vec3& n) const;
  const std::array<Vec3, 9>& coefficients() const { return coeffs_; }

 private:
  std::array<Vec3, 9> coeffs_;
};

}  // namespace rsibr
