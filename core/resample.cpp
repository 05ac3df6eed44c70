#include "core/resample.h"

#include "core/parallel.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace rsibr {

PixelFootprint pixel_footprint(const Layout& layout, const Vec2& p) {
  const double h = 0.25;
  const std::optional<Vec3> d0 = layout.direction(p);
  if (!d0) return {};
  // Derivative along one axis, central where both sides exist, else one-sided.
  auto derivative = [&](const Vec2& axis) -> Vec3 {
    const auto a = layout.direction(p + h * axis), b = layout.direction(p - h * axis);
    if (a && b) return (*a - *b) / (2 * h);
    if (a) return (*a - *d0) / h;
    if (b) return (*d0 - *b) / h;
    return Vec3::Zero();
  };
  const Vec3 jx = derivative(Vec2(1, 0)), jy = derivative(Vec2(0, 1));
  // Singular values of the 3x2 Jacobian [jx jy] from its 2x2 Gram matrix.
  const double a = jx.squaredNorm(), b = jx.dot(jy), c = jy.squaredNorm();
  const double mean = 0.5 * (a + c), dev = std::sqrt(std::max(0.0, 0.25 * (a - c) * (a - c) + b * b));
  return {std::sqrt(std::max(0.0, mean - dev)), std::sqrt(mean + dev)};
}

EnvMap resample(const EnvMap& src, const Layout& dst, const ResampleOptions& options) {
  EnvMap out = EnvMap::zeros(dst, src.channels());
  out.attributes = src.attributes;
  const int ch = src.channels();
  const int max_n = std::max(1, options.max_subsamples);
  std::atomic<int> rows_done{0};

  parallel_for_rows(dst.height(), [&](int r) {
    float* row = out.pixels.ptr<float>(r);
    float tap[kMaxChannels];
    double acc[kMaxChannels];
    for (int c = 0; c < dst.width(); ++c) {
      const Vec2 centre(c, r);
      float* px = row + std::size_t(c) * ch;
      std::optional<Vec3> dir = dst.direction(centre);
      bool partial_rim = false;
      if (dst.kind() == LayoutKind::Sphere) {
        // Only texels within a texel diagonal of the rim can straddle it.
        const Vec2 xy = sphere_map::disc_from_pixel(centre, dst.width(), dst.height());
        const double margin = 2.0 * std::sqrt(2.0) / std::min(dst.width(), dst.height());
        if (std::abs(xy.norm() - 1.0) < margin) {
          const double omega = dst.texel_solid_angle(c, r);
          partial_rim = omega > 0 && omega < 0.999 * 16.0 / (double(dst.width()) * dst.height());
        }
      }
      if (!dir && !partial_rim) continue;  // outside the sphere map's disc: no direction, stays 0

      int n = 1;
      if (dir) {
        const double extent = pixel_footprint(dst, centre).max_radians;
        const double src_step = pixel_footprint(src.layout, src.layout.pixel(*dir)).min_radians;
        const double k = src_step > 0 ? extent / src_step : double(max_n);
        n = std::clamp(int(std::ceil(options.supersampling * k - 1e-9)), 1, max_n);
      }
      if (partial_rim) n = std::max(n, 8);  // resolve the disc's edge inside the texel

      if (n == 1) {
        sample_bilinear(src, *dir, px);
        continue;
      }
      for (int k = 0; k < ch; ++k) acc[k] = 0.0;
      double wsum = 0.0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec2 q = centre + Vec2((i + 0.5) / n - 0.5, (j + 0.5) / n - 0.5);
          const double w = dst.solid_angle_density(q);
          if (!(w > 0)) continue;
          const std::optional<Vec3> d = dst.direction(q);
          if (!d) continue;
          sample_bilinear(src, *d, tap);
          for (int k = 0; k < ch; ++k) acc[k] += w * tap[k];
          wsum += w;
        }
      if (wsum > 0) {
        for (int k = 0; k < ch; ++k) px[k] = float(acc[k] / wsum);
      } else if (dir) {
        sample_bilinear(src, *dir, px);
      }
    }
    if (options.progress) {
      // Reported only from rows that finish; the callback itself decides how often to draw.
      const int done = ++rows_done;
      if (done % 16 == 0 || done == dst.height()) options.progress(double(done) / dst.height());
    }
  });
  return out;
}

}  // namespace rsibr
