#include "bake/brdf_lobes.h"

#include "bake/spec_text.h"

#include <stdexcept>

namespace rsibr {

BrdfLobe::BrdfLobe(std::shared_ptr<const Brdf> parent, CentralDirection part)
    : parent_(std::move(parent)), part_(part) {
  if (!parent_) throw std::invalid_argument("lobe: the parent BRDF is missing");
  if (!parent_->has_lobe(part_))
    throw std::invalid_argument(std::string("lobe: the BRDF has no ") + to_string(part_) + " lobe: " + parent_->spec());
}

Vec3 BrdfLobe::eval(const Vec3& wo, const Vec3& wi) const { return parent_->eval_lobe(part_, wo, wi); }

BrdfSample BrdfLobe::sample(const Vec3& wo, const Vec2& u) const {
  BrdfSample s = parent_->sample(wo, u);
  s.weight = s.valid ? Vec3(eval(wo, s.wi) / s.pdf) : Vec3::Zero();
  return s;
}

double BrdfLobe::pdf(const Vec3& wo, const Vec3& wi) const { return parent_->pdf(wo, wi); }

Vec3 BrdfLobe::eval_pdf(const Vec3& wo, const Vec3& wi, double* pdf_out) const {
  *pdf_out = parent_->pdf(wo, wi);
  return eval(wo, wi);
}

Vec3 BrdfLobe::albedo(const Vec3& wo) const { return parent_->albedo_lobe(part_, wo); }

double BrdfLobe::lobe_width(const Vec3& wo) const { return parent_->lobe_width_of(part_, wo); }

std::string BrdfLobe::spec() const {
  return spec_text::cat({"{type: lobe, part: ", to_string(part_), ", of: ", parent_->spec(), "}"});
}

std::vector<std::shared_ptr<const Brdf>> split_lobes(const std::shared_ptr<const Brdf>& brdf) {
  if (!brdf) throw std::invalid_argument("split_lobes: the BRDF is missing");
  std::vector<std::shared_ptr<const Brdf>> parts;
  for (const CentralDirection part : {CentralDirection::Normal, CentralDirection::Mirror})
    if (brdf->has_lobe(part)) parts.push_back(std::make_shared<BrdfLobe>(brdf, part));
  return parts;
}

}  // namespace rsibr
