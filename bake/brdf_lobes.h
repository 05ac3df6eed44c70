// Multi-lobe maps (the paper's future work): a BRDF split into a Normal-centred
// and a Mirror-centred part, each a Brdf of its own, so that each can be baked as its own map set
// (MapView::warp from the part's central direction) and the runtime sums the two warped blends
// (runtime/renderer.h sums map sets). The split itself is the BRDF's (Brdf::eval_lobe and friends,
// bake/brdf.h): clear coat = (coat + flakes) + binder; Lambert = Normal only; GGX, Phong,
// Blinn-Phong = Mirror only.
//
// Sampling of a part: the parent's own sampler and pdf, with weight = part eval / parent pdf.
// This is unbiased because the parts are non-negative and sum to the parent, so the parent's
// pdf is > 0 wherever the part is > 0 (the parent's sampler covers the part); it is not
// importance sampling of the part alone (a dim part gets few BRDF samples; MIS with environment
// samples, bake/mis_integrator.h, keeps its variance bounded). pdf() is therefore the parent's,
// integrates to 1 over the sphere, and the chi-square contract holds unchanged.
#pragma once

#include "bake/brdf.h"

#include <memory>
#include <string>
#include <vector>

namespace rsibr {

// One part of a BRDF. Spec: {type: lobe, part: normal|mirror, of: <the parent's spec>}.
class BrdfLobe final : public Brdf {
 public:
  // Throws std::invalid_argument when parent is null or has no such part (!has_lobe(part)).
  BrdfLobe(std::shared_ptr<const Brdf> parent, CentralDirection part);

  // parent.eval_lobe(part, wo, wi): cosine included, 0 below the horizon.
  Vec3 eval(const Vec3& wo, const Vec3& wi) const override;
  // The parent's sample with weight = eval / pdf (see the header comment).
  Sample sample(const Vec3& wo, const Vec2& u) const override;
  double pdf(const Vec3& wo, const Vec3& wi) const override;
  Vec3 eval_pdf(const Vec3& wo, const Vec3& wi, double* pdf_out) const override;
  // parent.albedo_lobe(part, wo) (the parent's accuracy).
  Vec3 albedo(const Vec3& wo) const override;
  CentralDirection central_direction() const override { return part_; }
  // parent.lobe_width_of(part, wo).
  double lobe_width(const Vec3& wo) const override;
  std::string spec() const override;

  const Brdf& parent() const { return *parent_; }
  CentralDirection part() const { return part_; }

 private:
  std::shared_ptr<const Brdf> parent_;
  CentralDirection part_;
};

// The non-empty parts of brdf (has_lobe), Normal first, then Mirror. Their evals sum to brdf's.
std::vector<std::shared_ptr<const Brdf>> split_lobes(const std::shared_ptr<const Brdf>& brdf);

}  // namespace rsibr
