// Monte Carlo with multiple importance sampling (Veach 1997) of the BRDF and the environment.
//
// Per texel, N BRDF samples x_i ~ p_b (Brdf::sample) and N environment samples y_j ~ p_e
// (EnvironmentDistribution: piecewise constant in luminance x solid angle), combined with the
// balance heuristic w_s(x) = p_s(x) / (p_b(x) + p_e(x)):
//
//   L_o ~= 1/N [ sum_i L(x_i) eval(wo, x_i) / (p_b(x_i) + p_e(x_i))
//              + sum_j L(y_j) eval(wo, y_j) / (p_b(y_j) + p_e(y_j)) ]
//
// Unbiased wherever p_b + p_e > 0 covers eval * L. L is the environment's texel value (the same
// piecewise-constant reconstruction the reference integrates), so for a sun the environment
// sampler's weight L/p_e is bounded by (total luminance power) / (texel luminance) and never
// explodes: no fireflies, no lost energy. Quality knob: IntegratorOptions::samples (N).
// Sample points: per texel, the N-point Hammersley set with a Cranley-Patterson rotation drawn
// from the texel's own stream (seed, texel index), one rotation per sampler: unbiased, stratified,
// deterministic, independent of threads.
// The brightest texels (a sun) are split off and integrated by quadrature (bake/bright_texels.h);
// the sampler sees the rest. Non-lat-long environments are resampled to lat-long (width = 2 x height) once.
#pragma once

#include "bake/bright_texels.h"
#include "bake/environment_distribution.h"
#include "bake/integrator.h"

namespace rsibr {

class MisIntegrator final : public Integrator {
 public:
  explicit MisIntegrator(const EnvMap& env);
  std::string name() const override { return "mis"; }
  cv::Mat radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                       const IntegratorOptions& options, const std::function<void(int)>& progress = {}) const override;
  const EnvironmentDistribution& distribution() const { return dist_; }
  const EnvironmentSplit& split() const { return split_; }

 private:
  EnvMap env_;  // lat-long
  EnvironmentSplit split_;
  EnvironmentDistribution dist_;  // of split_.remainder
  // RGB of split_.remainder at a texel (r * width + c), read in place: no copy of the map.
  Vec3 remainder_radiance(long texel) const;
};

// The environment in lat-long (itself when it already is).
EnvMap as_latlong(const EnvMap& env);

}  // namespace rsibr
