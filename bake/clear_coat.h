// Layered clear coat (automotive paint): a dielectric coat over a base of metallic flakes in a
// diffuse binder.
//
//   f_r(wo, wi) = f_coat(wo, wi)
//               + T(wo) T(wi) [ c f_flake(wo, wi) + (1 - c) rho / pi ],   T(w) = 1 - F_c(cos theta_w)
//
//   f_coat  : GGX (coat roughness) with the exact dielectric Fresnel of the coat index
//   f_flake : GGX (flake roughness) with the flakes' Fresnel (typically a conductor)
//   c       : flake coverage in [0,1];  rho: RGB albedo of the binder (diffuse)
//   F_c     : exact dielectric Fresnel of the coat at the MACRO normal (a smooth-coat
//             transmittance, also used when the coat is rough)
//
// Approximations (stated, not hidden): directions are not refracted into the coat (the base is
// evaluated with the outside wo, wi, so the base lobes are not narrowed by refraction), the coat
// does not absorb, light reflected back down by the coat's underside is lost (no inter-
// reflection), and there is no 1/eta^2 radiance compression. Each term is reciprocal, so f_r is.
// Energy: the coat reflects at most its GGX albedo ~ F_c(wo) and the base receives T(wo) of
// the rest, of which T(wi) <= 1 leaves; c f_flake + (1-c) rho/pi conserves energy on its own,
// so the total stays at or below 1 (measured in tests/bake/brdf_test.cpp for extreme settings).
//
// Sampling: a lobe (coat, flakes, binder) is chosen with probability proportional to an
// estimate of its albedo at wo (floored at 2% of the total for lobes that can reflect), then
// sampled by visible normals (GGX lobes) or by cos theta (binder); pdf = the mixture pdf
// sum_k p_k pdf_k, weight = eval / pdf.
#pragma once

#include "bake/brdf.h"
#include "bake/ggx.h"

#include <array>

namespace rsibr {

struct ClearCoatParams {
  double coat_ior = 1.5;                         // relative index of the coat, > 1
  double coat_roughness = 0.05;                  // GGX alpha of the coat, (0, 1]
  double flake_coverage = 0.3;                   // c, [0, 1]
  double flake_roughness = 0.3;                  // GGX alpha of the flakes, (0, 1]
  std::shared_ptr<const Fresnel> flake_fresnel;  // non-null
  Vec3 base_albedo = Vec3::Constant(0.5);        // rho, [0, 1]
};

class ClearCoatBrdf final : public Brdf {
 public:
  // Throws std::invalid_argument for values out of range.
  explicit ClearCoatBrdf(ClearCoatParams params);

  // f_r * cos(theta_i) (cosine included); 0 when wo or wi is below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  // Coat: GgxBrdf::albedo; flakes: graded midpoint rule of T(wi) times the flake sample weights;
  // binder: rho (1-c) T(wo) <T>, <T> the cosine-weighted mean of T (tabulated at construction).
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return CentralDirection::Mirror; }
  // The width (GgxBrdf / LambertBrdf measures) of the narrowest lobe that carries at least 1% of
  // the estimated albedo at wo: the coat's highlight usually, which sets the map resolution.
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

  // Multi-lobe split (bake/brdf_lobes.h):
  //   Mirror part = f_coat + T(wo) T(wi) c f_flake          (centred on the mirror direction)
  //   Normal part = T(wo) T(wi) (1 - c) rho / pi            (the binder, centred on n)
  // times cos theta_i, as eval. The Normal part exists when (1 - c) rho is not zero. albedo() is
  // the sum of the two parts' albedos; each part's width is lobe_width()'s rule over its own terms.
  bool has_lobe(CentralDirection part) const override;
  Vec3 eval_lobe(CentralDirection part, const Vec3& wo, const Vec3& wi) const override;
  Vec3 albedo_lobe(CentralDirection part, const Vec3& wo) const override;
  double lobe_width_of(CentralDirection part, const Vec3& wo) const override;

  const ClearCoatParams& params() const { return p_; }
  // CentralDirection selection probabilities at wo: coat, flakes, binder (sum to 1).
  std::array<double, 3> lobe_probabilities(const Vec3& wo) const;

 private:
  double transmittance(double cos_t) const;  // T = 1 - F_c(cos)
  std::array<double, 3> albedo_estimates(const Vec3& wo) const;

  ClearCoatParams p_;
  GgxBrdf coat_;
  GgxBrdf flakes_;
  double mean_transmittance_ = 0;  // <T> = int_0^1 T(mu) 2 mu dmu
};

}  // namespace rsibr
