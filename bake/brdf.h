// The BRDF interface of bake/: isotropic reflectance in the local shading frame.
//
// Frame and directions: the local shading frame has the surface normal n = +z. wo points from
// the surface toward the viewer, wi from the surface toward the light; both are unit vectors in
// that frame. Everything is RGB (linear Rec.709, like the rest of rsibr) and dimensionless;
// eval() is per steradian.
//
// The measure of every density is solid angle. Sampling contract (the same for every BRDF, so
// that one chi-square harness tests them all): sample() proposes wi anywhere on the sphere with
// density pdf(wo, wi); a proposal below the horizon (wi.z <= 0) is returned with valid = false
// and weight 0. Hence the integral of pdf(wo, .) over the whole sphere is 1 (for wo above the
// horizon) and the integral over the upper hemisphere is the probability of a valid sample.
// For wo on or below the horizon every sample is invalid (wi = 0, pdf = 0) and pdf() is 0.
#pragma once

#include "core/central_direction.h"
#include "core/vec.h"

#include <string>

namespace rsibr {

// The direction a lobe follows when the view changes: the runtime warps maps of Normal-lobe
// BRDFs with the normal warp and of Mirror-lobe BRDFs with the mirror warp.

struct BrdfSample {
  Vec3 wi = Vec3::Zero();      // proposed direction (unit), possibly below the horizon; 0 if none
  Vec3 weight = Vec3::Zero();  // eval(wo, wi) / pdf(wo, wi) (RGB); 0 when !valid
  double pdf = 0;              // pdf(wo, wi), solid angle
  bool valid = false;          // wi above the horizon and pdf > 0
};

class Brdf {
 public:
  using Sample = BrdfSample;
  virtual ~Brdf() = default;

  // f_r(wo, wi) * cos(theta_i): the cosine IS included. RGB, >= 0, finite for every pair of unit
  // vectors (including wo == n, grazing and wi == wo). 0 when wo.z <= 0 or wi.z <= 0.
  virtual Vec3 eval(const Vec3& wo, const Vec3& wi) const = 0;

  // Importance-samples wi for u in [0,1)^2; deterministic given (wo, u). See the contract above.
  virtual Sample sample(const Vec3& wo, const Vec2& u) const = 0;

  // Solid-angle density with which sample(wo, .) proposes wi, over the whole sphere.
  virtual double pdf(const Vec3& wo, const Vec3& wi) const = 0;

  // eval(wo, wi) and pdf(wo, wi) at once (integrators need both; classes share the work where
  // they can). Equal to calling the two.
  virtual Vec3 eval_pdf(const Vec3& wo, const Vec3& wi, double* pdf_out) const {
    *pdf_out = pdf(wo, wi);
    return eval(wo, wi);
  }

  // Directional albedo: integral over the upper hemisphere of eval(wo, wi) dwi (RGB, each
  // component in [0,1]): the radiance reflected toward wo under a white furnace (L_i = 1).
  // Closed form where exact, otherwise a deterministic quadrature (accuracy stated per class).
  virtual Vec3 albedo(const Vec3& wo) const = 0;

  virtual CentralDirection central_direction() const = 0;

  // Angular width of the lobe, radians: the half-angle of the cone about the lobe's central
  // direction (n for Normal lobes, the mirror direction of wo for Mirror lobes) that holds 90% of
  // the reflected energy, computed in closed form at normal incidence (horizon clipping and
  // off-specular shifts ignored; classes say where wo matters). Chooses map resolution and
  // view density; it is a measure, not an exact quantile for every wo.
  virtual double lobe_width(const Vec3& wo) const = 0;

  // The BRDF as one line of YAML (flow style) that make_brdf() parses back to the same BRDF
  // (bake/brdf_spec.h); the text of a map set's rsibr.material attribute.
  virtual std::string spec() const = 0;

  // Multi-lobe split (bake/brdf_lobes.h): the BRDF as the sum of a Normal-centred and a
  // Mirror-centred part, each baked as its own map set and warped with its own warp.
  //   eval_lobe(Normal, wo, wi) + eval_lobe(Mirror, wo, wi) = eval(wo, wi)   (to rounding)
  //   albedo_lobe(Normal, wo)   + albedo_lobe(Mirror, wo)   = albedo(wo)     (to rounding)
  // Same contract as eval (cosine included, local frame, 0 below the horizon) and albedo.
  // Defaults: the whole BRDF is its central_direction() part and the other part is empty.
  // has_lobe(part) is false when the part is identically zero (then eval_lobe and albedo_lobe
  // return 0 and lobe_width_of is meaningless).
  virtual bool has_lobe(CentralDirection part) const { return part == central_direction(); }
  virtual Vec3 eval_lobe(CentralDirection part, const Vec3& wo, const Vec3& wi) const {
    return has_lobe(part) ? eval(wo, wi) : Vec3::Zero();
  }
  virtual Vec3 albedo_lobe(CentralDirection part, const Vec3& wo) const {
    return has_lobe(part) ? albedo(wo) : Vec3::Zero();
  }
  // lobe_width() of the part alone, about the part's own central direction.
  virtual double lobe_width_of(CentralDirection part, const Vec3& wo) const {
    (void)part;
    return lobe_width(wo);
  }
};

// The energy fraction that lobe_width() refers to.
inline constexpr double kLobeEnergyFraction = 0.9;

}  // namespace rsibr
