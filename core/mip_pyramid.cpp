#include "core/mip_pyramid.h"

#include "core/resample.h"

#include <algorithm>
#include <cmath>

namespace rsibr {

MipPyramid::MipPyramid(const EnvMap& base) {
  levels_.push_back(base);
  const int min_size = base.layout.kind() == LayoutKind::Sphere ? 2 : 4;
  for (;;) {
    const Layout& top = levels_.back().layout;
    const int next = top.size() / 2;
    if (next < min_size) break;
    const Layout smaller = Layout::with_size(top.kind(), next);
    if (smaller == top) break;
    levels_.push_back(resample(levels_.back(), smaller));
  }
}

void MipPyramid::sample(const Vec3& dir, double lod, float* out) const {
  const int ch = levels_.front().channels();
  lod = std::clamp(std::isfinite(lod) ? lod : 0.0, 0.0, double(levels_.size() - 1));
  const int l0 = int(std::floor(lod));
  const int l1 = std::min(l0 + 1, levels() - 1);
  const float f = float(lod - l0);
  sample_bilinear(levels_[std::size_t(l0)], dir, out);
  if (f == 0.f || l1 == l0) return;
  float upper[kMaxChannels];
  sample_bilinear(levels_[std::size_t(l1)], dir, upper);
  for (int k = 0; k < ch; ++k) out[k] = (1 - f) * out[k] + f * upper[k];
}

double MipPyramid::lod_for_solid_angle(const Vec3& dir, double omega) const {
  const Layout& L = levels_.front().layout;
  const double texel = L.solid_angle_density(L.pixel(dir));
  if (!(texel > 0) || !(omega > 0)) return 0.0;
  return std::max(0.0, 0.5 * std::log2(omega / texel));
}

}  // namespace rsibr
