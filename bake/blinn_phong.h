// Normalised Blinn-Phong: a cos^e lobe of the half vector h = (wo+wi)/|wo+wi|.
//
//   D(h)  = (e+1)/(2 pi) (h.n)^e                    normalised: int_H D(h) dh = 1
//   f_r   = rho D(h) / (4 (wo.h) max(cos theta_o, cos theta_i))
//
// The denominator is Ashikhmin & Shirley's (2000); it makes the energy bound provable:
// with dwi = 4 (wo.h) dh,
//   albedo(wo) = rho int D(h) cos theta_i / max(cos theta_o, cos theta_i) dh <= rho int D = rho.
// f_r is symmetric in wo and wi (wo.h = wi.h), hence reciprocal. Fresnel is not included.
#pragma once

#include "bake/brdf.h"

namespace rsibr {

class BlinnPhongBrdf final : public Brdf {
 public:
  // rho: RGB reflectance in [0,1]; exponent e > 0 (finite). Throws std::invalid_argument.
  BlinnPhongBrdf(const Vec3& rho, double exponent);

  // f_r * cos(theta_i) (cosine included); 0 when wo or wi is below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  // h from D (power-cosine about n), wi = reflect(wo, h): pdf = D(h) / (4 |wo.h|) on the sphere
  // (h = the upper-hemisphere half vector); proposals below the horizon are
  // invalid; weight = rho cos theta_i / max(cos theta_o, cos theta_i).
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  // Midpoint rule over the sampler's unit square (256^2 points): error <= 4e-4, worst at grazing
  // wo where cos_i / max(cos_o, cos_i) ramps within a thin band (measured in brdf_test.cpp).
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return CentralDirection::Mirror; }
  // At normal incidence wi is at 2 theta_h from r = n; energy within theta_h of n:
  // 1 - cos^(e+1) theta_h = 0.9  =>  width = 2 acos(0.1^(1/(e+1))).
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

 private:
  Vec3 rho_;
  double e_;
};

}  // namespace rsibr
