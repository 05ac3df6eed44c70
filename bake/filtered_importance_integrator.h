// Filtered importance sampling (Křivánek & Colbert 2008, "Real-time shading with filtered
// importance sampling"): BRDF samples only, each reading a MIP-mapped environment at a level
// whose texels cover about the solid angle the sample stands for:
//
//   Omega_s = 1 / (N pdf(wi)),   lod = 0.5 log2(Omega_s / Omega_texel(wi)) + bias
//   L_o    ~= 1/N sum_i L_mip(w_i, lod_i) * eval(wo, wi_i) / pdf(wi_i)
//
// The N sample points are the Hammersley set with one Cranley-Patterson rotation per seed (the
// same for every texel): no per-texel noise, a smooth, slightly blurred (biased) map whose bias
// falls as N grows. Quality knob: IntegratorOptions::samples; IntegratorOptions::fis_lod_bias.
// Any layout (core/mip_pyramid.h).
#pragma once

#include "bake/bright_texels.h"
#include "bake/integrator.h"
#include "core/mip_pyramid.h"

namespace rsibr {

class FilteredImportanceIntegrator final : public Integrator {
 public:
  explicit FilteredImportanceIntegrator(const EnvMap& env);
  std::string name() const override { return "fis"; }
  cv::Mat radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                       const IntegratorOptions& options, const std::function<void(int)>& progress = {}) const override;

 private:
  Layout latlong_;
  EnvironmentSplit split_;  // the sun by quadrature (bake/bright_texels.h), the rest filtered
  MipPyramid pyramid_;      // of split_.remainder
};

}  // namespace rsibr
