#include "pipeline/torus_mesh.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

// Point (u around +Y, w around the tube): p = (R + r cos w) (sin u, 0, cos u) + r sin w * Y,
// outward normal n = cos w (sin u, 0, cos u) + sin w * Y. dp/du x dp/dw points along n for the
// index order below (u then w), which makes the triangles counter-clockwise seen from outside.
Mesh torus_mesh(double R, double r, int segments, int sides) {
  if (segments < 3 || sides < 3 || !(r > 0) || !(r < R) || !std::isfinite(R))
    throw std::invalid_argument("torus: need segments, sides >= 3 and 0 < minor radius < major radius");
  Mesh m;
  const double two_pi = 2 * 3.14159265358979323846;
  for (int i = 0; i < segments; ++i) {
    const double u = two_pi * i / segments;
    const Eigen::Vector3d radial(std::sin(u), 0, std::cos(u));
    for (int k = 0; k < sides; ++k) {
      const double w = two_pi * k / sides;
      const Eigen::Vector3d n = std::cos(w) * radial + std::sin(w) * Eigen::Vector3d::UnitY();
      const Eigen::Vector3d p = R * radial + r * n;
      m.positions.push_back(p.cast<float>());
      m.normals.push_back(n.normalized().cast<float>());
    }
  }
  auto at = [&](int i, int k) { return uint32_t(((i + segments) % segments) * sides + (k + sides) % sides); };
  for (int i = 0; i < segments; ++i)
    for (int k = 0; k < sides; ++k) {
      const uint32_t a = at(i, k), b = at(i + 1, k), c = at(i + 1, k + 1), d = at(i, k + 1);
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  return m;
}

}  // namespace rsibr
