#include "bake/fresnel.h"

#include "bake/spec_text.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {
double clamp_cos(double c) { return std::clamp(std::abs(c), 0.0, 1.0); }
}  // namespace

SchlickFresnel::SchlickFresnel(const Vec3& f0) : f0_(f0) {
  if (!(f0.minCoeff() >= 0.0 && f0.maxCoeff() <= 1.0))
    throw std::invalid_argument("schlick fresnel: f0 must be in [0,1]");
}

Vec3 SchlickFresnel::eval(double cos_t) const {
  const double m = 1.0 - clamp_cos(cos_t);
  const double m2 = m * m;
  return f0_ + (Vec3::Ones() - f0_) * (m2 * m2 * m);
}

std::string SchlickFresnel::spec() const { return spec_text::cat({"{type: schlick, f0: ", spec_text::rgb(f0_), "}"}); }

DielectricFresnel::DielectricFresnel(double eta) : eta_(eta) {
  if (!(eta > 0.0 && std::isfinite(eta))) throw std::invalid_argument("dielectric fresnel: ior must be finite and > 0");
}

Vec3 DielectricFresnel::eval(double cos_t) const { return Vec3::Constant(fresnel_dielectric(cos_t, eta_)); }

std::string DielectricFresnel::spec() const {
  return spec_text::cat({"{type: dielectric, ior: ", spec_text::number(eta_), "}"});
}

ConductorFresnel::ConductorFresnel(const Vec3& eta, const Vec3& k) : eta_(eta), k_(k) {
  if (!(eta.minCoeff() > 0.0 && eta.allFinite()))
    throw std::invalid_argument("conductor fresnel: eta must be finite and > 0");
  if (!(k.minCoeff() >= 0.0 && k.allFinite()))
    throw std::invalid_argument("conductor fresnel: k must be finite and >= 0");
}

Vec3 ConductorFresnel::eval(double cos_t) const {
  Vec3 f;
  for (int c = 0; c < 3; ++c) f[c] = fresnel_conductor(cos_t, eta_[c], k_[c]);
  return f;
}

std::string ConductorFresnel::spec() const {
  return spec_text::cat({"{type: conductor, eta: ", spec_text::rgb(eta_), ", k: ", spec_text::rgb(k_), "}"});
}

// Snell: sin_t = sin_i / eta;  cos_t = sqrt(1 - sin_i^2 / eta^2)   (no real root: TIR, F = 1)
//   r_s = (cos_i - eta cos_t) / (cos_i + eta cos_t)
//   r_p = (eta cos_i - cos_t) / (eta cos_i + cos_t)
//   F   = (r_s^2 + r_p^2) / 2
// At cos_i = 0 both are -1, so F = 1 exactly at grazing.
double fresnel_dielectric(double cos_i, double eta) {
  cos_i = clamp_cos(cos_i);
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return std::min(1.0, 0.5 * (rs * rs + rp * rp));
}

// The same amplitudes with a complex index eta = n + i k and the principal complex root
//   cos_t = sqrt(1 - sin_i^2 / eta^2),   F = (|r_s|^2 + |r_p|^2) / 2.
// For k = 0 below the critical angle cos_t is real (the dielectric case); beyond it cos_t is
// purely imaginary and |r_s| = |r_p| = 1 (TIR).
double fresnel_complex(double cos_i, std::complex<double> eta) {
  using C = std::complex<double>;
  cos_i = clamp_cos(cos_i);
  const double sin2_i = 1.0 - cos_i * cos_i;
  const C cos_t = std::sqrt(C(1.0) - sin2_i / (eta * eta));
  const C rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const C rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const double f = 0.5 * (std::norm(rs) + std::norm(rp));
  return std::isfinite(f) ? std::min(1.0, f) : 1.0;
}

// Real form of the complex amplitudes above. With s2 = sin_i^2, c = cos_i and
//   t0 = eta^2 - k^2 - s2,   a^2 + b^2 = sqrt(t0^2 + 4 eta^2 k^2),   a = sqrt((a^2 + b^2 + t0) / 2)
// (eta^2 cos_t^2 = a^2 - b^2 + 2iab up to the sign convention), the squared magnitudes are
//   R_s = (a^2 + b^2 + c^2 - 2ac) / (a^2 + b^2 + c^2 + 2ac)
//   R_p = R_s (c^2 (a^2 + b^2) + s2^2 - 2 a c s2) / (c^2 (a^2 + b^2) + s2^2 + 2 a c s2)
// and F = (R_s + R_p) / 2. At c = 0: R_s = R_p = 1. With k = 0 beyond the critical angle a = 0
// and R_s = R_p = 1 (total internal reflection).
// Accuracy: within 1e-11 of the complex form for eta in [0.05, 3], k in [0, 10] (tested).
double fresnel_conductor(double cos_i, double eta, double k) {
  const double c = clamp_cos(cos_i);
  const double c2 = c * c, s2 = 1.0 - c2;
  const double eta2 = eta * eta, k2 = k * k;
  const double t0 = eta2 - k2 - s2;
  const double ab2 = std::sqrt(t0 * t0 + 4.0 * eta2 * k2);
  // (a^2 + b^2 + t0)(a^2 + b^2 - t0) = 4 eta^2 k^2: the second form has no cancellation for t0 < 0
  // (a weakly absorbing metal beyond its critical angle).
  const double a = std::sqrt(t0 >= 0 ? 0.5 * (ab2 + t0) : (ab2 - t0 > 0 ? 2.0 * eta2 * k2 / (ab2 - t0) : 0.0));
  const double t1 = ab2 + c2, t2 = 2.0 * a * c;
  const double rs = t1 + t2 > 0 ? (t1 - t2) / (t1 + t2) : 1.0;
  const double t3 = c2 * ab2 + s2 * s2, t4 = t2 * s2;
  const double rp = t3 + t4 > 0 ? rs * (t3 - t4) / (t3 + t4) : rs;
  const double f = 0.5 * (rs + rp);
  return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 1.0;
}

}  // namespace rsibr
