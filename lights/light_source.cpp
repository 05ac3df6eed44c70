#include "lights/light_source.h"

namespace rsibr::light_kernels {

std::vector<Vec3> cap_points(const Vec3& d, double rho, int rings) {
  const Vec3 axis = d.normalized();
  if (rings <= 1 && !(rho > 0)) return {axis};
  rings = std::max(rings, 1);
  const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  std::vector<Vec3> out;
  const double c0 = std::cos(rho);
  for (int i = 0; i < rings; ++i) {
    // Ring i holds the band cos t in [1 - (i+1) s, 1 - i s], s = (1 - cos rho) / rings: equal areas.
    const double ct = 1 - (i + 0.5) / rings * (1 - c0), st = std::sqrt(std::max(0.0, 1 - ct * ct));
    const int az = 4 * rings;
    for (int j = 0; j < az; ++j) {
      const double phi = 2 * kPi * (j + 0.5 * (i % 2)) / az;
      out.push_back(ct * axis + st * (std::cos(phi) * e1 + std::sin(phi) * e2));
    }
  }
  return out;
}

}  // namespace rsibr::light_kernels
