#include "bake/lambert.h"

#include "bake/sample_warps.h"
#include "bake/spec_text.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

LambertBrdf::LambertBrdf(const Vec3& rho) : rho_(rho) {
  if (!(rho.minCoeff() >= 0.0 && rho.maxCoeff() <= 1.0))
    throw std::invalid_argument("lambert: albedo must be in [0,1]");
}

Vec3 LambertBrdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  return rho_ * (wi.z() / kPi);
}

BrdfSample LambertBrdf::sample(const Vec3& wo, const Vec2& u) const {
  Sample s;
  if (!(wo.z() > 0)) return s;
  s.wi = warp::square_to_cosine_hemisphere(u);
  s.pdf = warp::cosine_hemisphere_pdf(s.wi.z());
  s.valid = s.pdf > 0;  // only on the measure-zero rim is the proposal not strictly above
  if (s.valid) s.weight = rho_;
  return s;
}

double LambertBrdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0)) return 0.0;
  return warp::cosine_hemisphere_pdf(wi.z());
}

Vec3 LambertBrdf::albedo(const Vec3& wo) const { return wo.z() > 0 ? rho_ : Vec3::Zero(); }

double LambertBrdf::lobe_width(const Vec3&) const { return std::asin(std::sqrt(kLobeEnergyFraction)); }

std::string LambertBrdf::spec() const {
  return spec_text::cat({"{type: lambert, albedo: ", spec_text::rgb(rho_), "}"});
}

}  // namespace rsibr
