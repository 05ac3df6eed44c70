#include "bake/clear_coat.h"

#include "bake/sample_warps.h"
#include "bake/spec_text.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {
ClearCoatParams validated(ClearCoatParams p) {
  if (!(p.coat_ior > 1.0 && std::isfinite(p.coat_ior)))
    throw std::invalid_argument("clearcoat: coat ior must be finite and > 1");
  if (!(p.flake_coverage >= 0.0 && p.flake_coverage <= 1.0))
    throw std::invalid_argument("clearcoat: flake coverage must be in [0,1]");
  if (!(p.base_albedo.minCoeff() >= 0.0 && p.base_albedo.maxCoeff() <= 1.0))
    throw std::invalid_argument("clearcoat: base albedo must be in [0,1]");
  if (!p.flake_fresnel) throw std::invalid_argument("clearcoat: flake fresnel is missing");
  return p;
}
}  // namespace

ClearCoatBrdf::ClearCoatBrdf(ClearCoatParams params)
    : p_(validated(std::move(params))),
      coat_(p_.coat_roughness, std::make_shared<DielectricFresnel>(p_.coat_ior)),
      flakes_(p_.flake_roughness, p_.flake_fresnel) {
  // <T> = int_0^1 T(mu) 2 mu dmu = int_0^1 T(sqrt(t)) dt  (t = mu^2), midpoint rule.
  const int n = 8192;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += transmittance(std::sqrt((i + 0.5) / n));
  mean_transmittance_ = sum / n;
}

double ClearCoatBrdf::transmittance(double cos_t) const { return 1.0 - fresnel_dielectric(cos_t, p_.coat_ior); }

Vec3 ClearCoatBrdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  const double c = p_.flake_coverage;
  Vec3 base = (1.0 - c) * p_.base_albedo * (wi.z() / kPi);
  if (c > 0) base += c * flakes_.eval(wo, wi);
  return coat_.eval(wo, wi) + transmittance(wo.z()) * transmittance(wi.z()) * base;
}

std::array<double, 3> ClearCoatBrdf::albedo_estimates(const Vec3& wo) const {
  const double t = transmittance(wo.z());
  const double c = p_.flake_coverage;
  return {1.0 - t,                                                       // coat ~ F_c(wo)
          t * t * c * p_.flake_fresnel->eval(wo.z()).mean(),             // flakes: wi ~ mirror of wo
          t * mean_transmittance_ * (1.0 - c) * p_.base_albedo.mean()};  // binder
}

std::array<double, 3> ClearCoatBrdf::lobe_probabilities(const Vec3& wo) const {
  std::array<double, 3> e = albedo_estimates(wo);
  double sum = e[0] + e[1] + e[2];
  if (!(sum > 0)) return {1.0, 0.0, 0.0};
  for (double& x : e)
    if (x > 0) x = std::max(x, 0.02 * sum);
  sum = e[0] + e[1] + e[2];
  return {e[0] / sum, e[1] / sum, e[2] / sum};
}

BrdfSample ClearCoatBrdf::sample(const Vec3& wo, const Vec2& u) const {
  Sample s;
  if (!(wo.z() > 0)) return s;
  const auto p = lobe_probabilities(wo);
  // Choose a lobe with u.x and rescale u.x to [0,1) within the chosen interval.
  const auto rescale = [](double x, double lo, double w) { return std::min((x - lo) / w, std::nextafter(1.0, 0.0)); };
  if (u.x() < p[0]) {
    s.wi = coat_.sample(wo, Vec2(rescale(u.x(), 0.0, p[0]), u.y())).wi;
  } else if (u.x() < p[0] + p[1]) {
    s.wi = flakes_.sample(wo, Vec2(rescale(u.x(), p[0], p[1]), u.y())).wi;
  } else {
    const double w = 1.0 - p[0] - p[1];
    s.wi = warp::square_to_cosine_hemisphere(Vec2(w > 0 ? rescale(u.x(), p[0] + p[1], w) : 0.5, u.y()));
  }
  if (s.wi.isZero()) return s;
  s.pdf = pdf(wo, s.wi);
  s.valid = s.wi.z() > 0 && s.pdf > 0;
  if (s.valid) s.weight = eval(wo, s.wi) / s.pdf;
  return s;
}

double ClearCoatBrdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0)) return 0.0;
  const auto p = lobe_probabilities(wo);
  double pdf = 0;
  if (p[0] > 0) pdf += p[0] * coat_.pdf(wo, wi);
  if (p[1] > 0) pdf += p[1] * flakes_.pdf(wo, wi);
  if (p[2] > 0) pdf += p[2] * warp::cosine_hemisphere_pdf(wi.z());
  return pdf;
}

Vec3 ClearCoatBrdf::albedo(const Vec3& wo) const {
  return albedo_lobe(CentralDirection::Mirror, wo) + albedo_lobe(CentralDirection::Normal, wo);
}

bool ClearCoatBrdf::has_lobe(CentralDirection part) const {
  if (part == CentralDirection::Mirror) return true;  // the coat (ior > 1) always reflects
  return p_.flake_coverage < 1.0 && p_.base_albedo.maxCoeff() > 0.0;
}

Vec3 ClearCoatBrdf::eval_lobe(CentralDirection part, const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  const double c = p_.flake_coverage;
  const double tt = transmittance(wo.z()) * transmittance(wi.z());
  if (part == CentralDirection::Normal) return tt * ((1.0 - c) * p_.base_albedo * (wi.z() / kPi));
  Vec3 f = coat_.eval(wo, wi);
  if (c > 0) f += tt * (c * flakes_.eval(wo, wi));
  return f;
}

Vec3 ClearCoatBrdf::albedo_lobe(CentralDirection part, const Vec3& wo) const {
  if (!(wo.z() > 0)) return Vec3::Zero();
  const double t_o = transmittance(wo.z());
  const double c = p_.flake_coverage;
  if (part == CentralDirection::Normal) return (t_o * (1.0 - c) * mean_transmittance_) * p_.base_albedo;
  Vec3 a = coat_.albedo(wo);
  if (c > 0) {
    a += (t_o * c) * warp::square_graded_mean(256, [&](const Vec2& u) -> Vec3 {
           const Sample smp = flakes_.sample(wo, u);
           return smp.valid ? Vec3(smp.weight * transmittance(smp.wi.z())) : Vec3::Zero();
         });
  }
  return a;
}

double ClearCoatBrdf::lobe_width_of(CentralDirection part, const Vec3& wo) const {
  if (part == CentralDirection::Normal) return std::asin(std::sqrt(kLobeEnergyFraction));
  // lobe_width()'s rule over coat and flakes: the narrowest carrying >= 1% of the part's estimate.
  const auto e = albedo_estimates(wo.z() > 0 ? wo : Vec3(0, 0, 1));
  const double sum = e[0] + e[1];
  const double widths[2] = {ggx_lobe_width(p_.coat_roughness), ggx_lobe_width(p_.flake_roughness)};
  double w = kPi;  // above every GGX width (2 atan(3 alpha) < pi)
  for (int k = 0; k < 2; ++k)
    if (e[std::size_t(k)] >= 0.01 * sum) w = std::min(w, widths[k]);
  return w < kPi ? w : widths[0];
}

double ClearCoatBrdf::lobe_width(const Vec3& wo) const {
  const auto e = albedo_estimates(wo.z() > 0 ? wo : Vec3(0, 0, 1));
  const double sum = e[0] + e[1] + e[2];
  const double widths[3] = {ggx_lobe_width(p_.coat_roughness), ggx_lobe_width(p_.flake_roughness),
                            std::asin(std::sqrt(kLobeEnergyFraction))};
  double w = widths[2];
  for (int k = 0; k < 3; ++k)
    if (e[std::size_t(k)] >= 0.01 * sum) w = std::min(w, widths[k]);
  return w;
}

std::string ClearCoatBrdf::spec() const {
  using spec_text::number;
  return spec_text::cat(
      {"{type: clearcoat, coat: {ior: ", number(p_.coat_ior), ", roughness: ", number(p_.coat_roughness),
       "}, flakes: {coverage: ", number(p_.flake_coverage), ", roughness: ", number(p_.flake_roughness),
       ", fresnel: ", p_.flake_fresnel->spec(), "}, base: {albedo: ", spec_text::rgb(p_.base_albedo), "}}"});
}

}  // namespace rsibr
