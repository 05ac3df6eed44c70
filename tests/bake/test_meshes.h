// Meshes built in code for the renderer tests: an icosphere with exact sphere normals and a quad.
#pragma once

#include "core/mesh.h"
#include "core/vec.h"

#include <cmath>
#include <map>
#include <utility>

namespace rsibr::test {

// The icosahedron subdivided `levels` times (20 * 4^levels triangles), vertices on the sphere of
// `radius` about `centre`, normals exactly radial, triangles counter-clockwise seen from outside.
inline Mesh icosphere(int levels, double radius = 1.0, const Vec3& centre = Vec3::Zero()) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                         {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (Vec3& x : v) x.normalize();
  std::vector<std::array<uint32_t, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& f : t) {
      const uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    t = std::move(next);
  }
  Mesh m;
  for (const Vec3& x : v) {
    m.positions.push_back((centre + radius * x).cast<float>());
    m.normals.push_back(x.cast<float>());
  }
  m.triangles = t;
  return m;
}

// Appends the square [-h, h]^2 in the plane y = `height`, facing +Y (normals +Y).
inline void add_ground(Mesh& m, double h, double height = 0.0) {
  const uint32_t base = uint32_t(m.positions.size());
  const float y = float(height), s = float(h);
  m.positions.insert(m.positions.end(), {{-s, y, -s}, {s, y, -s}, {s, y, s}, {-s, y, s}});
  m.normals.insert(m.normals.end(), 4, Eigen::Vector3f(0, 1, 0));
  // Counter-clockwise seen from +Y.
  m.triangles.push_back({base, base + 2, base + 1});
  m.triangles.push_back({base, base + 3, base + 2});
}

}  // namespace rsibr::test
