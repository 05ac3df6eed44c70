#include "bake/ggx.h"

#include "bake/sample_warps.h"
#include "bake/shading_frame.h"
#include "bake/spec_text.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

GgxBrdf::GgxBrdf(double roughness, std::shared_ptr<const Fresnel> fresnel)
    : dist_{roughness}, fresnel_(std::move(fresnel)) {
  if (!(roughness > 0.0 && roughness <= 1.0)) throw std::invalid_argument("ggx: roughness must be in (0,1]");
  if (!fresnel_) throw std::invalid_argument("ggx: fresnel is missing");
}

Vec3 GgxBrdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  const Vec3 h = shading::half_vector_up(wo, wi);
  const double oh = wo.dot(h);
  if (!(oh > 0)) return Vec3::Zero();
  const double g2 = dist_.G2(wo, wi);
  if (!(g2 > 0)) return Vec3::Zero();
  return fresnel_->eval(oh) * (dist_.D(h) * g2 / (4.0 * wo.z()));
}

BrdfSample GgxBrdf::sample(const Vec3& wo, const Vec2& u) const {
  Sample s;
  if (!(wo.z() > 0)) return s;
  const Vec3 m = dist_.sample_visible(wo, u);
  s.wi = shading::reflect(wo, m).normalized();
  s.pdf = pdf(wo, s.wi);
  s.valid = s.wi.z() > 0 && s.pdf > 0;
  if (s.valid) {
    const double g1 = dist_.G1(wo);
    s.weight = fresnel_->eval(wo.dot(m)) * (dist_.G2(wo, s.wi) / g1);
  }
  return s;
}

double GgxBrdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0)) return 0.0;
  const Vec3 h = shading::half_vector_up(wo, wi);
  if (!(wo.dot(h) > 0)) return 0.0;
  return dist_.G1(wo) * dist_.D(h) / (4.0 * wo.z());
}

Vec3 GgxBrdf::eval_pdf(const Vec3& wo, const Vec3& wi, double* pdf_out) const {
  *pdf_out = 0;
  if (!(wo.z() > 0)) return Vec3::Zero();
  const Vec3 h = shading::half_vector_up(wo, wi);
  const double oh = wo.dot(h);
  if (!(oh > 0)) return Vec3::Zero();
  const double d = dist_.D(h);
  *pdf_out = dist_.G1(wo) * d / (4.0 * wo.z());
  if (!(wi.z() > 0)) return Vec3::Zero();
  const double g2 = dist_.G2(wo, wi);
  if (!(g2 > 0)) return Vec3::Zero();
  return fresnel_->eval(oh) * (d * g2 / (4.0 * wo.z()));
}

Vec3 GgxBrdf::albedo(const Vec3& wo) const {
  if (!(wo.z() > 0)) return Vec3::Zero();
  return warp::square_graded_mean(256, [&](const Vec2& u) -> Vec3 {
    const Sample smp = sample(wo, u);
    return smp.valid ? smp.weight : Vec3::Zero();
  });
}

double ggx_lobe_width(double alpha) {
  return 2.0 * std::atan(alpha * std::sqrt(kLobeEnergyFraction / (1.0 - kLobeEnergyFraction)));
}

double GgxBrdf::lobe_width(const Vec3&) const { return ggx_lobe_width(dist_.alpha); }

std::string GgxBrdf::spec() const {
  return spec_text::cat(
      {"{type: ggx, roughness: ", spec_text::number(dist_.alpha), ", fresnel: ", fresnel_->spec(), "}"});
}

}  // namespace rsibr
