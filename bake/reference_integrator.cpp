#include "bake/reference_integrator.h"

#include <stdexcept>

namespace rsibr {

std::vector<ReferenceIntegrator::Texel> ReferenceIntegrator::texels_of(const EnvMap& env) {
  std::vector<Texel> out;
  const Layout& l = env.layout;
  const int ch = env.channels();
  if (ch < 3) throw std::invalid_argument("reference integrator: the environment needs 3 channels");
  out.reserve(std::size_t(l.texel_count()));
  for (int r = 0; r < l.height(); ++r) {
    const float* row = env.pixels.ptr<float>(r);
    for (int c = 0; c < l.width(); ++c) {
      const auto d = l.texel_direction(c, r);
      const double omega = l.texel_solid_angle(c, r);
      if (!d || !(omega > 0)) continue;
      const Vec3 L(row[c * ch], row[c * ch + 1], row[c * ch + 2]);
      if (L == Vec3::Zero()) continue;
      out.push_back({d->normalized(), L * omega});
    }
  }
  return out;
}

ReferenceIntegrator::ReferenceIntegrator(const EnvMap& env)
    : base_(env), full_(texels_of(env)), mutex_(std::make_unique<std::mutex>()) {}

const std::vector<ReferenceIntegrator::Texel>& ReferenceIntegrator::level_for(int width) const {
  if (width <= 0 || width >= base_.layout.width()) return full_;
  std::lock_guard<std::mutex> lock(*mutex_);
  if (!pyramid_) {
    pyramid_ = std::make_unique<MipPyramid>(base_);
    levels_.resize(std::size_t(pyramid_->levels()));
  }
  int i = 0;
  while (i + 1 < pyramid_->levels() && pyramid_->level(i).layout.width() > width) ++i;
  auto& level = levels_[std::size_t(i)];
  if (level.empty()) level = texels_of(pyramid_->level(i));
  return level;
}

cv::Mat ReferenceIntegrator::radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                                          const IntegratorOptions& options,
                                          const std::function<void(int)>& progress) const {
  const std::vector<Texel>& texels = level_for(options.reference_width);
  return integrator_detail::for_each_texel(
      size, view, world_from_view, options.texel_mask,
      [&](long, const integrator_detail::TexelFrame& f) {
        const Vec3 n = f.frame.normal();
        Vec3 sum = Vec3::Zero();
        for (const Texel& t : texels) {
          if (!(n.dot(t.dir) > 0)) continue;
          sum += brdf.eval(f.wo, f.frame.to_local(t.dir)).cwiseProduct(t.radiance);
        }
        return sum;
      },
      progress);
}

}  // namespace rsibr
