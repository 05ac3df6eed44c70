#include "core/resample.h"

#include "core/parallel.h"
#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace rsibr {

PixelFootprint pixel_footprint(const Layout& layout, const Vec2& p) {
  // Closed forms where the Jacobian is simple; central differences otherwise.
  switch (layout.kind()) {
    case LayoutKind::LatLong: {
      // Latitude step pi/(H-1); longitude step 2 pi/(W-1), shortened by cos(latitude).
      const double dlat = kPi / (layout.height() - 1), dlon = 2 * kPi / (layout.width() - 1);
      const double across = std::abs(std::cos(0.5 * kPi - dlat * p.y())) * dlon;
      return {std::min(dlat, across), std::max(dlat, across)};
    }
    case LayoutKind::Sphere: {
      // Mirror ball, rho = |(x,y)|: radially d(theta)/d(rho) = 2/sqrt(1-rho^2), tangentially
      // 2 sqrt(1-rho^2); one pixel is 2/W (2/H) in disc units.
      const Vec2 xy = sphere_map::disc_from_pixel(p, layout.width(), layout.height());
      const double z = std::sqrt(std::max(1e-12, 1.0 - xy.squaredNorm()));
      if (xy.squaredNorm() > 1.0) return {};
      const double fine = 2.0 / std::max(layout.width(), layout.height());
      const double coarse = 2.0 / std::min(layout.width(), layout.height());
      return {2 * z * fine, 2 / z * coarse};
    }
    default: break;
  }
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
  const auto lookup = options.reconstruction == Reconstruction::Nearest ? &sample_nearest : &sample_bilinear;

  // Local peak magnitude of the source (max over channels and the 3x3 neighbourhood) and the
  // energy of |L|, for the energy-driven tap count.
  EnvMap peak;
  double energy = 0;
  if (options.energy_tolerance > 0) {
    peak.layout = src.layout;
    cv::Mat magnitude(src.pixels.rows, src.pixels.cols, CV_32FC1);
    for (int r = 0; r < src.pixels.rows; ++r) {
      const float* p = src.pixels.ptr<float>(r);
      float* m = magnitude.ptr<float>(r);
      for (int c = 0; c < src.pixels.cols; ++c) {
        float v = 0;
        for (int k = 0; k < ch; ++k) v = std::max(v, std::isfinite(p[c * ch + k]) ? std::abs(p[c * ch + k]) : 0.f);
        m[c] = v;
      }
    }
    cv::dilate(magnitude, peak.pixels, cv::Mat::ones(3, 3, CV_8U));
    energy = integral(EnvMap{src.layout, magnitude, {}})[0];
  }

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
      if (dir && energy > 0) {
        float local_peak = 0;
        sample_nearest(peak, *dir, &local_peak);
        const double omega = dst.solid_angle_density(centre);
        const double need = std::sqrt(local_peak * omega / (options.energy_tolerance * energy));
        if (need > n) n = std::min(max_n, int(std::ceil(need)));
      }

      if (n == 1) {
        lookup(src, *dir, px);
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
          lookup(src, *d, tap);
          for (int k = 0; k < ch; ++k) acc[k] += w * tap[k];
          wsum += w;
        }
      if (wsum > 0) {
        for (int k = 0; k < ch; ++k) px[k] = float(acc[k] / wsum);
      } else if (dir) {
        lookup(src, *dir, px);
      } else if (const auto d = dst.texel_direction(c, r)) {
        lookup(src, *d, px);  // a sliver of the disc that no tap reached
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
