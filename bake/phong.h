// Normalised (energy-conserving) Phong: a cos^e lobe about the mirror direction of wo.
//
//   f_r(wo, wi) = rho (e+2)/(2 pi) max(0, r.wi)^e,   r = reflect(wo, n) = (-wo.x, -wo.y, wo.z)
//
// (Lafortune & Willems 1994). r.wi = reflect(wi, n).wo, so f_r is reciprocal. At normal
// incidence the directional albedo is exactly rho; elsewhere the horizon clips the lobe and the
// albedo is smaller (never above rho: tests/bake/brdf_test.cpp measures it).
#pragma once

#include "bake/brdf.h"

namespace rsibr {

class PhongBrdf final : public Brdf {
 public:
  // rho: RGB specular reflectance in [0,1]; exponent e > 0 (finite). Throws std::invalid_argument.
  PhongBrdf(const Vec3& rho, double exponent);

  // f_r * cos(theta_i) (cosine included); 0 when wo or wi is below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  // wi from the cos^e lobe about r: pdf = (e+1)/(2 pi) max(0, r.wi)^e on the sphere (proposals
  // below the horizon are invalid); weight = rho (e+2)/(e+1) cos(theta_i).
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  // One-dimensional quadrature (4096 points) of the closed-form azimuthal integral.
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return CentralDirection::Mirror; }
  // At normal incidence theta_i = alpha, so the energy within alpha of r = n is
  // int_0^alpha cos^(e+1) sin / int_0^pi/2 (same) = 1 - cos^(e+2) alpha = 0.9
  //   =>  alpha = acos(0.1^(1/(e+2)))   (exact there; wo-independent measure elsewhere).
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

 private:
  Vec3 rho_;
  double e_;
};

}  // namespace rsibr
