// Lambertian (perfectly diffuse) reflection: f_r = rho / pi.
#pragma once

#include "bake/brdf.h"

namespace rsibr {

class LambertBrdf final : public Brdf {
 public:
  // rho: RGB diffuse reflectance in [0,1]. Throws std::invalid_argument otherwise.
  explicit LambertBrdf(const Vec3& rho);

  // rho/pi * cos(theta_i) (cosine included); 0 below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  // Cosine-weighted hemisphere (never below the horizon): pdf = cos(theta_i)/pi, weight = rho.
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  // Exactly rho for every wo above the horizon (0 below).
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return CentralDirection::Normal; }
  // Energy within theta of n: int_0^theta 2 cos sin dtheta = sin^2 theta  =>  asin(sqrt(0.9)),
  // exact for every wo (about 71.6 degrees).
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

  const Vec3& rho() const { return rho_; }

 private:
  Vec3 rho_;
};

}  // namespace rsibr
