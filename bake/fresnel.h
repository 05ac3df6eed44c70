// Fresnel reflectance: the fraction of light reflected by a (micro)facet, as a function of the
// cosine of the angle between the incident direction and the facet normal.
//
// Contract of Fresnel::eval(cos_t): light arrives from the outside medium (the one wo and wi
// live in); cos_t = |cos| is clamped to [0,1]; the result is RGB in [0,1], unpolarised (the mean
// of the s and p reflectances). Indices of refraction are relative: inside over outside.
#pragma once

#include "core/vec.h"

#include <complex>
#include <memory>
#include <string>

namespace rsibr {

class Fresnel {
 public:
  virtual ~Fresnel() = default;
  virtual Vec3 eval(double cos_t) const = 0;
  // Flow-style YAML, e.g. "{type: dielectric, ior: 1.5}" (parsed by bake/brdf_spec.h).
  virtual std::string spec() const = 0;
};

// F = 1 for every angle: no Fresnel effect (white-furnace tests). Spec {type: none}.
class NoFresnel final : public Fresnel {
 public:
  Vec3 eval(double) const override { return Vec3::Ones(); }
  std::string spec() const override { return "{type: none}"; }
};

// Schlick's approximation F = F0 + (1 - F0) (1 - cos)^5, F0 RGB in [0,1]. Spec {type: schlick, f0}.
class SchlickFresnel final : public Fresnel {
 public:
  explicit SchlickFresnel(const Vec3& f0);
  Vec3 eval(double cos_t) const override;
  std::string spec() const override;
  const Vec3& f0() const { return f0_; }

 private:
  Vec3 f0_;
};

// Exact unpolarised Fresnel of a smooth interface to a dielectric of real relative index eta > 0
// (grey). eta < 1 (light inside the denser medium) has total internal reflection: F = 1 beyond
// the critical angle. Spec {type: dielectric, ior}.
class DielectricFresnel final : public Fresnel {
 public:
  explicit DielectricFresnel(double eta);
  Vec3 eval(double cos_t) const override;
  std::string spec() const override;
  double eta() const { return eta_; }

 private:
  double eta_;
};

// Exact unpolarised Fresnel of a conductor with complex relative index eta + i k per RGB channel
// (eta > 0, k >= 0). With k = 0 it is the dielectric formula. Spec {type: conductor, eta, k}.
class ConductorFresnel final : public Fresnel {
 public:
  ConductorFresnel(const Vec3& eta, const Vec3& k);
  Vec3 eval(double cos_t) const override;
  std::string spec() const override;

 private:
  Vec3 eta_, k_;
};

// The formulas themselves (cos_i: cosine of the angle of incidence, clamped to [0,1]).
double fresnel_dielectric(double cos_i, double eta);
double fresnel_complex(double cos_i, std::complex<double> eta);
// The same value as fresnel_complex(cos_i, {eta, k}) in real arithmetic (no complex division or
// complex square root: about 5x faster; what ConductorFresnel evaluates). Agreement is tested.
double fresnel_conductor(double cos_i, double eta, double k);

}  // namespace rsibr
