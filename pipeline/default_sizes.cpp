#include "pipeline/default_sizes.h"

#include "core/vec.h"

#include <algorithm>
#include <cmath>

namespace rsibr {

namespace {

int round_up(double v, int multiple) { return int(std::ceil(v / multiple - 1e-9)) * multiple; }

}  // namespace

double ball_pixel_radius(const BallCone& cone, const LensModel& lens) {
  const Vec3 a = cone.axis.normalized();
  const Vec3 u = (std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized(), v = a.cross(u);
  const Vec2 c = lens.project(a);
  double sum = 0;
  for (int k = 0; k < 4; ++k) {
    const double phi = 0.5 * kPi * k;
    const Vec3 limb =
        std::cos(cone.half_angle) * a + std::sin(cone.half_angle) * (std::cos(phi) * u + std::sin(phi) * v);
    sum += (lens.project(limb) - c).norm();
  }
  return std::isfinite(sum) ? sum / 4 : 0.0;
}

int default_map_size(BallKind kind, double radius_px) {
  const int cap = kind == BallKind::grey ? 128 : kind == BallKind::glossy ? 256 : 2048;
  const double r = std::isfinite(radius_px) ? std::max(radius_px, 0.0) : 0.0;
  return std::clamp(round_up(2 * r, 16), 64, cap);
}

int default_probe_width(int chrome_map_size) { return std::clamp(round_up(kPi * chrome_map_size / 2, 64), 256, 4096); }

std::size_t map_set_bytes(int n, std::size_t views) { return std::size_t(n) * std::size_t(n) * 20 * views; }

std::size_t probe_bytes(int width) { return std::size_t(width) * std::size_t(width / 2) * 36; }

}  // namespace rsibr
