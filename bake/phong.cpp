#include "bake/phong.h"

#include "bake/sample_warps.h"
#include "bake/shading_frame.h"
#include "bake/spec_text.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {
Vec3 mirror_of(const Vec3& wo) { return Vec3(-wo.x(), -wo.y(), wo.z()); }
}  // namespace

PhongBrdf::PhongBrdf(const Vec3& rho, double exponent) : rho_(rho), e_(exponent) {
  if (!(rho.minCoeff() >= 0.0 && rho.maxCoeff() <= 1.0)) throw std::invalid_argument("phong: albedo must be in [0,1]");
  if (!(exponent > 0.0 && std::isfinite(exponent)))
    throw std::invalid_argument("phong: exponent must be finite and > 0");
}

Vec3 PhongBrdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0 && wi.z() > 0)) return Vec3::Zero();
  const double c = mirror_of(wo).dot(wi);
  if (!(c > 0)) return Vec3::Zero();
  return rho_ * ((e_ + 2.0) / (2.0 * kPi) * std::pow(std::min(c, 1.0), e_) * wi.z());
}

BrdfSample PhongBrdf::sample(const Vec3& wo, const Vec2& u) const {
  Sample s;
  if (!(wo.z() > 0)) return s;
  const Vec3 r = mirror_of(wo).normalized();
  s.wi = (shading::Frame::around(r).to_world(warp::square_to_power_cosine(u, e_))).normalized();
  s.pdf = pdf(wo, s.wi);
  s.valid = s.wi.z() > 0 && s.pdf > 0;
  if (s.valid) s.weight = rho_ * ((e_ + 2.0) / (e_ + 1.0) * s.wi.z());
  return s;
}

double PhongBrdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z() > 0)) return 0.0;
  return warp::power_cosine_pdf(std::min(1.0, mirror_of(wo).dot(wi)), e_);
}

// Write wi in the frame of r = (sin b, 0, cos b)-ish, b = theta_o, with alpha = angle(wi, r) and
// phi its azimuth about r:  cos theta_i = a + b' cos phi,  a = cos b cos alpha, b' = sin b sin alpha.
//   int_0^2pi max(0, a + b' cos phi) dphi = 2 pi a                       (a >= b')
//                                          = 0                           (a <= -b')
//                                          = 2 a phi0 + 2 b' sin phi0    (phi0 = acos(-a/b'))
// so albedo = rho (e+2)/(2 pi) int_0^1 mu^e g(mu) dmu,  mu = cos alpha. With mu = t^(1/(e+1))
// (the sampling CDF), mu^e dmu = dt/(e+1): albedo = rho (e+2)/(2 pi (e+1)) int_0^1 g(mu(t)) dt,
// integrated by the midpoint rule on 4096 intervals (g is continuous, with one kink).
Vec3 PhongBrdf::albedo(const Vec3& wo) const {
  if (!(wo.z() > 0)) return Vec3::Zero();
  const double cb = std::min(1.0, wo.z()), sb = std::sqrt(std::max(0.0, 1.0 - cb * cb));
  const int n = 4096;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) / n;
    const double mu = std::pow(t, 1.0 / (e_ + 1.0));
    const double sa = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double a = cb * mu, b = sb * sa;
    double g;
    if (a >= b) {
      g = 2.0 * kPi * a;
    } else if (a <= -b) {
      g = 0.0;
    } else {
      const double phi0 = std::acos(std::clamp(-a / b, -1.0, 1.0));
      g = 2.0 * a * phi0 + 2.0 * b * std::sin(phi0);
    }
    sum += g;
  }
  return rho_ * ((e_ + 2.0) / (2.0 * kPi * (e_ + 1.0)) * sum / n);
}

double PhongBrdf::lobe_width(const Vec3&) const {
  return std::acos(std::pow(1.0 - kLobeEnergyFraction, 1.0 / (e_ + 2.0)));
}

std::string PhongBrdf::spec() const {
  return spec_text::cat({"{type: phong, albedo: ", spec_text::rgb(rho_), ", exponent: ", spec_text::number(e_), "}"});
}

}  // namespace rsibr
