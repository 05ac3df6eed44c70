#include "core/sphere_mesh.h"

#include "core/vec.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

Mesh sphere_mesh(const Eigen::Vector3f& centre, float radius, int rings, int segments) {
  if (!(radius > 0) || rings < 2 || segments < 3)
    throw std::invalid_argument("sphere mesh: radius > 0, rings >= 2 and segments >= 3 needed");
  Mesh m;
  // Vertex (i, j): latitude ring i of rings + 1 (0 at +Y), longitude j of segments + 1 (the seam
  // duplicated so uvs stay continuous).
  for (int i = 0; i <= rings; ++i) {
    const double theta = kPi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      const Eigen::Vector3f n(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                              float(std::sin(theta) * std::cos(phi)));
      m.positions.push_back(centre + radius * n);
      m.normals.push_back(n);
      m.uvs.emplace_back(float(j) / segments, 1.f - float(i) / rings);
    }
  }
  const auto at = [&](int i, int j) { return std::uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      // Seen from outside, +phi runs to the right and +theta down: (i, j), (i + 1, j), (i, j + 1)
      // is counter-clockwise (the rings next to the poles have one triangle per segment).
      if (i > 0) m.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + 1 < rings) m.triangles.push_back({at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  return m;
}

}  // namespace rsibr
