#include "bake/blinn_phong.h"

#include "bake/sample_warps.h"
#include "bake/shading_frame.h"
#include "bake/spec_text.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

BlinnPhongBrdf::BlinnPhongBrdf(const Vec3& rho, double exponent) : rho_(rho), e_(exponent) {
  if (!(rho.minCoeff() >= 0.0 && rho.maxCoeff() <= 1.0))
    throw std::invalid_argument("blinn_phong: albedo must be in [0,1]");
  if (!(exponent > 0.0 && std::isfinite(exponent)))
    throw std::invalid_argument("blinn_phong: exponent must be finite and > 0");
}

Vec3 BlinnPhongBrdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  const Vec3 h = shading::half_vector_up(wo, wi);
  const double oh = wo.dot(h);
  if (!(oh > 0)) return Vec3::Zero();
  const double d = warp::power_cosine_pdf(std::min(1.0, h.z()), e_);
  // f_r cos_i = rho D cos_i / (4 oh max(cos_o, cos_i)); cos_i / max(...) <= 1 keeps it finite.
  return rho_ * (d / (4.0 * oh) * (wi.z() / std::max(wo.z(), wi.z())));
}

BrdfSample BlinnPhongBrdf::sample(const Vec3& wo, const Vec2& u) const {
  Sample s;
  if (!(wo.z() > 0)) return s;
  const Vec3 h = warp::square_to_power_cosine(u, e_);
  s.wi = shading::reflect(wo, h).normalized();
  s.pdf = pdf(wo, s.wi);
  s.valid = s.wi.z() > 0 && s.pdf > 0;
  if (s.valid) s.weight = rho_ * (s.wi.z() / std::max(wo.z(), s.wi.z()));
  return s;
}

double BlinnPhongBrdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0)) return 0.0;
  // Proposals with wo.h < 0 land below the horizon but still count in the sphere density.
  const Vec3 h = shading::half_vector_up(wo, wi);
  const double oh = std::abs(wo.dot(h));
  if (!(oh > 0)) return 0.0;
  return warp::power_cosine_pdf(std::min(1.0, h.z()), e_) / (4.0 * oh);
}

Vec3 BlinnPhongBrdf::albedo(const Vec3& wo) const {
  if (!(wo.z() > 0)) return Vec3::Zero();
  const double s = warp::square_midpoint_mean(256, [&](const Vec2& u) {
    const Sample smp = sample(wo, u);
    return smp.valid ? smp.wi.z() / std::max(wo.z(), smp.wi.z()) : 0.0;
  });
  return rho_ * s;
}

double BlinnPhongBrdf::lobe_width(const Vec3&) const {
  return 2.0 * std::acos(std::pow(1.0 - kLobeEnergyFraction, 1.0 / (e_ + 1.0)));
}

std::string BlinnPhongBrdf::spec() const {
  return spec_text::cat(
      {"{type: blinn_phong, albedo: ", spec_text::rgb(rho_), ", exponent: ", spec_text::number(e_), "}"});
}

}  // namespace rsibr
