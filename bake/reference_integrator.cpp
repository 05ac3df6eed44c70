#include "bake/reference_integrator.h"

#include "core/parallel.h"

#include <algorithm>
#include <stdexcept>

namespace rsibr {

void ReferenceIntegrator::append_row_texels(const EnvMap& env, int r, std::vector<Texel>& out) {
  const Layout& l = env.layout;
  const int ch = env.channels();
  if (ch < 3) throw std::invalid_argument("reference integrator: the environment needs 3 channels");
  const float* row = env.pixels.ptr<float>(r);
  for (int c = 0; c < l.width(); ++c) {
    const Vec3 L(row[c * ch], row[c * ch + 1], row[c * ch + 2]);
    if (L == Vec3::Zero()) continue;
    const double omega = l.texel_solid_angle(c, r);
    if (!(omega > 0)) continue;
    const auto d = l.texel_direction(c, r);
    if (!d) continue;
    out.push_back({d->normalized(), L * omega});
  }
}

std::vector<ReferenceIntegrator::Texel> ReferenceIntegrator::texels_of(const EnvMap& env) {
  // Rows in parallel into their own slices of one list, in row order (the same list on any
  // number of threads): each row is visited twice, to count and to fill.
  const int h = env.layout.height();
  std::vector<std::size_t> start(static_cast<std::size_t>(h) + 1, 0);
  const int ch = env.channels();
  parallel_for_rows(h, [&](int r) {
    // What append_row_texels keeps: light and solid angle (a texel with solid angle has a direction).
    const float* p = env.pixels.ptr<float>(r);
    std::size_t n = 0;
    for (int c = 0; c < env.layout.width(); ++c)
      n += (p[c * ch] != 0.f || p[c * ch + 1] != 0.f || p[c * ch + 2] != 0.f) && env.layout.texel_solid_angle(c, r) > 0;
    start[std::size_t(r) + 1] = n;
  });
  for (int r = 0; r < h; ++r) start[std::size_t(r) + 1] += start[std::size_t(r)];
  std::vector<Texel> out(start.back());
  parallel_for_rows(h, [&](int r) {
    std::vector<Texel> row;
    row.reserve(start[std::size_t(r) + 1] - start[std::size_t(r)]);
    append_row_texels(env, r, row);
    if (row.size() != start[std::size_t(r) + 1] - start[std::size_t(r)])
      throw std::logic_error("reference integrator: a row's texels were miscounted");
    std::copy(row.begin(), row.end(), out.begin() + std::ptrdiff_t(start[std::size_t(r)]));
  });
  return out;
}

ReferenceIntegrator::ReferenceIntegrator(const EnvMap& env) : base_(env), mutex_(std::make_unique<std::mutex>()) {}

const std::vector<ReferenceIntegrator::Texel>& ReferenceIntegrator::level_for(int width) const {
  std::lock_guard<std::mutex> lock(*mutex_);
  // Built on first use: a bake over a coarser level never lists the full map's texels.
  if (width <= 0 || width >= base_.layout.width()) {
    if (!full_) full_ = std::make_unique<std::vector<Texel>>(texels_of(base_));
    return *full_;
  }
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
