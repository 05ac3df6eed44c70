// The ground truth: deterministic quadrature over the environment's texels with exact solid
// angles (bake/integrator.h for the texel contract):
//
//   L_o(p) = sum_q L(q) * eval(wo, B^T w_q) * Omega(q)      over texels q with n.w_q > 0
//
// w_q = Layout::texel_direction, Omega(q) = Layout::texel_solid_angle (they sum to 4 pi). This
// is exact for a piecewise-constant environment up to the variation of eval within one texel, so
// it needs the environment's texels to be small against the BRDF lobe. Quality knob:
// IntegratorOptions::reference_width picks a MIP level (exact energy per level); cost per map
// texel = that level's texel count. Any layout.
#pragma once

#include "bake/integrator.h"
#include "core/mip_pyramid.h"

#include <memory>
#include <mutex>
#include <vector>

namespace rsibr {

class ReferenceIntegrator final : public Integrator {
 public:
  explicit ReferenceIntegrator(const EnvMap& env);
  std::string name() const override { return "reference"; }
  cv::Mat radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                       const IntegratorOptions& options, const std::function<void(int)>& progress = {}) const override;

  // The environment as a list of (direction, L * Omega) over its texels with non-zero radiance and
  // solid angle (exact solid angles): the quadrature this integrator and the SH projection share.
  struct Texel {
    Vec3 dir;       // world, unit
    Vec3 radiance;  // L * Omega (RGB)
  };
  static std::vector<Texel> texels_of(const EnvMap& env);
  // Appends row r's texels (those with light and solid angle) to out, in column order.
  static void append_row_texels(const EnvMap& env, int r, std::vector<Texel>& out);

 private:
  const std::vector<Texel>& level_for(int width) const;

  EnvMap base_;
  mutable std::unique_ptr<std::vector<Texel>> full_;  // every texel of base_, made by level_for
  mutable std::unique_ptr<MipPyramid> pyramid_;       // built on first use of reference_width
  mutable std::vector<std::vector<Texel>> levels_;    // filled lazily (guarded by mutex_)
  mutable std::unique_ptr<std::mutex> mutex_;
};

}  // namespace rsibr
