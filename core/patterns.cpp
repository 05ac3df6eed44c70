#include "core/patterns.h"

#include "core/parallel.h"

#include <cmath>

namespace rsibr {

EnvMap render_pattern(const Radiance& f, const Layout& layout, int m) {
  EnvMap out = EnvMap::zeros(layout, 3);
  m = std::max(1, m);
  parallel_for_rows(layout.height(), [&](int r) {
    float* row = out.pixels.ptr<float>(r);
    for (int c = 0; c < layout.width(); ++c) {
      Vec3 acc = Vec3::Zero();
      double wsum = 0;
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
          const Vec2 q = m == 1 ? Vec2(c, r) : Vec2(c + (i + 0.5) / m - 0.5, r + (j + 0.5) / m - 0.5);
          const auto d = layout.direction(q);
          if (!d) continue;
          const double w = m == 1 ? 1.0 : layout.solid_angle_density(q);
          if (!(w > 0)) continue;
          acc += w * f(*d);
          wsum += w;
        }
      if (wsum > 0) {
        acc /= wsum;
      } else if (const auto d = layout.texel_direction(c, r)) {
        acc = f(*d);  // a sphere-map texel whose cell only grazes the disc
      }
      for (int k = 0; k < 3; ++k) row[3 * c + k] = float(acc[k]);
    }
  });
  return out;
}

namespace patterns {

Radiance constant(const Vec3& rgb) {
  return [rgb](const Vec3&) { return rgb; };
}

Radiance direction_coded() {
  return [](const Vec3& d) { return Vec3(0.5 * (d + Vec3(1, 1, 1))); };
}

Radiance latlong_checker(double degrees, double lo, double hi) {
  const double step = degrees * kPi / 180.0;
  return [=](const Vec3& d) {
    const double lat = std::asin(std::clamp(d.y(), -1.0, 1.0)), lon = std::atan2(d.x(), d.z());
    const long a = long(std::floor(lat / step)), b = long(std::floor(lon / step));
    const double v = ((a + b) % 2 == 0) ? hi : lo;
    return Vec3(v, v, v);
  };
}

Radiance sun_and_sky(const Vec3& sun_dir, double sun_radius, const Vec3& sun_rgb, const Vec3& zenith_rgb,
                     const Vec3& horizon_rgb) {
  const Vec3 s = sun_dir.normalized();
  const double cos_r = std::cos(sun_radius);
  return [=](const Vec3& d) {
    const double h = std::max(0.0, d.y());
    Vec3 L = horizon_rgb + (zenith_rgb - horizon_rgb) * std::sqrt(h);
    if (d.dot(s) >= cos_r) L += sun_rgb;
    return L;
  };
}

}  // namespace patterns
}  // namespace rsibr
