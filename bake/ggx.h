// GGX / Trowbridge-Reitz microfacet reflection with height-correlated Smith masking-shadowing
// and a pluggable Fresnel term (bake/fresnel.h). Single scattering only: energy lost to
// multiple scattering between microfacets is not added back, so the albedo with F = 1 is below 1
// for rough surfaces.
//
//   f_r(wo, wi) = D(h) G2(wo, wi) F(wo.h) / (4 cos theta_o cos theta_i),  h = (wo+wi)/|wo+wi|
//   eval        = f_r cos theta_i = D(h) G2 F / (4 cos theta_o)
// Sampling by visible normals: m ~ D_o, wi = reflect(wo, m), dwi/dm = 4 (wo.m), so
//   pdf(wi) = D_o(m) / (4 wo.m) = G1(wo) D(h) / (4 cos theta_o),   weight = F(wo.m) G2 / G1(wo).
#pragma once

#include "bake/brdf.h"
#include "bake/fresnel.h"
#include "bake/ggx_distribution.h"

#include <memory>

namespace rsibr {

class GgxBrdf final : public Brdf {
 public:
  // roughness = GGX alpha in (0, 1]; fresnel non-null. Throws std::invalid_argument otherwise.
  GgxBrdf(double roughness, std::shared_ptr<const Fresnel> fresnel);

  // f_r * cos(theta_i) (cosine included); 0 when wo or wi is below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  // Visible-normal sampling (above); proposals below the horizon are invalid.
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  // G1(wo) D(h) / (4 cos theta_o) with h the upper-hemisphere half vector, 0 where wo.h <= 0;
  // integrates to 1 over the sphere.
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  Vec3 eval_pdf(const Vec3& wo, const Vec3& wi, double* pdf_out) const override;
  // Midpoint rule over the visible-normal square (256^2 points, graded toward the rim where the
  // tail lies: warp::square_graded_mean) of F(wo.m) G2/G1(wo) for the proposals above the
  // horizon; tests/bake/brdf_test.cpp measures its error against an independent hemisphere
  // quadrature of eval.
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return CentralDirection::Mirror; }
  // At normal incidence the reflected energy within theta_h of n is (ignoring G and F) the CDF
  // of D(m) m.z:  tan^2 / (a^2 + tan^2) = 0.9  =>  tan theta_h = 3 a; wi is at 2 theta_h from r:
  // width = 2 atan(3 alpha).
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

  double roughness() const { return dist_.alpha; }
  const GgxDistribution& distribution() const { return dist_; }
  const Fresnel& fresnel() const { return *fresnel_; }

 private:
  GgxDistribution dist_;
  std::shared_ptr<const Fresnel> fresnel_;
};

// 2 atan(3 alpha): the width measure of a GGX lobe (see GgxBrdf::lobe_width).
double ggx_lobe_width(double alpha);

}  // namespace rsibr
