#include "bake/filtered_importance_integrator.h"

#include "bake/mis_integrator.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

namespace {
EnvMap checked_latlong(const EnvMap& env) {
  if (env.channels() < 3) throw std::invalid_argument("fis: the environment needs 3 channels");
  return as_latlong(env);
}
}  // namespace

FilteredImportanceIntegrator::FilteredImportanceIntegrator(const EnvMap& env)
    : split_(split_bright_texels(checked_latlong(env))), pyramid_(split_.remainder) {
  latlong_ = split_.remainder.layout;
}

cv::Mat FilteredImportanceIntegrator::radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view,
                                                   int size, const IntegratorOptions& options,
                                                   const std::function<void(int)>& progress) const {
  if (options.samples < 1) throw std::invalid_argument("fis: samples must be >= 1");
  const int n = options.samples;
  // Hammersley points, rotated by one offset drawn from the seed.
  integrator_detail::TexelRng rng(options.seed, ~std::uint64_t(0));
  const Vec2 shift = rng.uniform2();
  std::vector<Vec2> points(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) points[std::size_t(i)] = integrator_detail::rotated_hammersley(i, n, shift);
  return integrator_detail::for_each_texel(
      size, view, world_from_view, options.texel_mask,
      [&](long, const integrator_detail::TexelFrame& t) {
        const shading::Frame& frame = t.frame;
        const Vec3& wo = t.wo;
        Vec3 sum = Vec3::Zero();
        float L[kMaxChannels];
        for (const Vec2& u : points) {
          const BrdfSample s = brdf.sample(wo, u);
          if (!s.valid || !(s.pdf > 0)) continue;
          const Vec3 w = frame.to_world(s.wi);
          const double lod = pyramid_.lod_for_solid_angle(w, 1.0 / (n * s.pdf)) + options.fis_lod_bias;
          pyramid_.sample(w, lod, L);
          sum += s.weight.cwiseProduct(Vec3(L[0], L[1], L[2]));
        }
        return Vec3(sum / n + bright_texel_radiance(brdf, frame, wo, split_, latlong_));
      },
      progress);
}

}  // namespace rsibr
