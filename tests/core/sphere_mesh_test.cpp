// The ball's mesh (core/sphere_mesh.h): every vertex on the sphere with its outward unit normal,
// every triangle non-degenerate and counter-clockwise seen from outside, and the surface closed.
#include "core/sphere_mesh.h"

#include <gtest/gtest.h>

#include <map>
#include <utility>

namespace rsibr {
namespace {

TEST(SphereMesh, VerticesLieOnTheSphereWithOutwardUnitNormals) {
  const Eigen::Vector3f c(0.5f, -1.f, 2.f);
  const Mesh m = sphere_mesh(c, 2.f, 8, 12);
  ASSERT_EQ(m.positions.size(), m.normals.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_NEAR((m.positions[i] - c).norm(), 2.f, 1e-5f);
    EXPECT_NEAR(m.normals[i].norm(), 1.f, 1e-6f);
    EXPECT_NEAR((m.positions[i] - c).normalized().dot(m.normals[i]), 1.f, 1e-5f);
  }
}

TEST(SphereMesh, TrianglesFaceOutwardAndCloseTheSurface) {
  const Eigen::Vector3f c = Eigen::Vector3f::Zero();
  const int rings = 6, segments = 10;
  const Mesh m = sphere_mesh(c, 1.f, rings, segments);
  EXPECT_EQ(m.triangles.size(), std::size_t(2 * segments * (rings - 1)));
  // Positions welded (the seam and the poles are duplicated vertices): each undirected edge of the
  // welded surface is used by exactly two triangles, once in each direction.
  std::map<std::tuple<int, int, int>, int> weld;
  auto id = [&](std::uint32_t v) {
    const Eigen::Vector3f p = m.positions[v] * 1e4f;
    const auto key = std::make_tuple(int(std::lround(p.x())), int(std::lround(p.y())), int(std::lround(p.z())));
    return weld.emplace(key, int(weld.size())).first->second;
  };
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f a = m.positions[t[0]], b = m.positions[t[1]], d = m.positions[t[2]];
    const Eigen::Vector3f n = (b - a).cross(d - a);
    ASSERT_GT(n.norm(), 1e-6f);
    EXPECT_GT(n.dot((a + b + d) / 3 - c), 0.f);  // counter-clockwise from outside
    for (int e = 0; e < 3; ++e) ++directed[{id(t[std::size_t(e)]), id(t[std::size_t((e + 1) % 3)])}];
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "an open edge";
  }
}

TEST(SphereMesh, BadArgumentsAreRefused) {
  EXPECT_THROW(sphere_mesh(Eigen::Vector3f::Zero(), 0.f), std::invalid_argument);
  EXPECT_THROW(sphere_mesh(Eigen::Vector3f::Zero(), 1.f, 1, 8), std::invalid_argument);
  EXPECT_THROW(sphere_mesh(Eigen::Vector3f::Zero(), 1.f, 4, 2), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
