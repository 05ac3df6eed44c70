#include "bake/mis_integrator.h"

#include "core/resample.h"

#include <stdexcept>

namespace rsibr {

EnvMap as_latlong(const EnvMap& env) {
  if (env.layout.kind() == LayoutKind::LatLong) return env;
  // About as many texels as the source.
  const int h = std::max(4, int(std::lround(std::sqrt(double(env.layout.texel_count()) / 2.0))));
  return resample(env, Layout(LayoutKind::LatLong, 2 * h, h));
}

MisIntegrator::MisIntegrator(const EnvMap& env)
    : env_(as_latlong(env)), split_(split_bright_texels(env_)), dist_(split_.remainder) {
  if (!split_.remainder.pixels.isContinuous()) split_.remainder.pixels = split_.remainder.pixels.clone();
}

Vec3 MisIntegrator::remainder_radiance(long texel) const {
  const int ch = split_.remainder.channels();
  const float* p = split_.remainder.pixels.ptr<float>(0) + std::size_t(texel) * std::size_t(ch);
  return Vec3(p[0], p[1], p[2]);
}

cv::Mat MisIntegrator::radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                                    const IntegratorOptions& options, const std::function<void(int)>& progress) const {
  if (options.samples < 1) throw std::invalid_argument("mis: samples must be >= 1");
  const int n = options.samples;
  return integrator_detail::for_each_texel(
      size, view, world_from_view, options.texel_mask,
      [&](long index, const integrator_detail::TexelFrame& t) {
        const shading::Frame& frame = t.frame;
        const Vec3& wo = t.wo;
        // Stratified: a Hammersley set per sampler, rotated by the texel's own random shifts.
        integrator_detail::TexelRng rng(options.seed, std::uint64_t(index));
        const Vec2 shift_b = rng.uniform2(), shift_e = rng.uniform2();
        Vec3 sum = Vec3::Zero();
        for (int i = 0; i < n; ++i) {
          // BRDF sample: f = weight * pdf (sample() has evaluated it already).
          const BrdfSample b = brdf.sample(wo, integrator_detail::rotated_hammersley(i, n, shift_b));
          if (b.valid) {
            const long q = dist_.texel_of(frame.to_world(b.wi));
            const double pe = dist_.texel_pdf(q);
            sum += (b.weight * b.pdf).cwiseProduct(remainder_radiance(q)) / (b.pdf + pe);
          }
          // Environment sample.
          const EnvironmentDistribution::Sample e = dist_.sample(integrator_detail::rotated_hammersley(i, n, shift_e));
          if (e.pdf > 0) {
            const Vec3 wi = frame.to_local(e.dir);
            if (wi.z() > 0) {
              double pb = 0;
              const Vec3 f = brdf.eval_pdf(wo, wi, &pb);
              if (f != Vec3::Zero()) sum += f.cwiseProduct(remainder_radiance(e.texel)) / (pb + e.pdf);
            }
          }
        }
        return Vec3(sum / n + bright_texel_radiance(brdf, frame, wo, split_, env_.layout));
      },
      progress);
}

}  // namespace rsibr
