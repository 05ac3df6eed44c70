// The built-in torus (pipeline/torus_mesh.h): on the surface, unit outward normals, consistent winding.
#include "pipeline/torus_mesh.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

TEST(TorusMesh, PointsLieOnTheTorusWithUnitOutwardNormals) {
  const double R = 1.0, r = 0.4;
  const Mesh m = torus_mesh(R, r, 24, 12);
  ASSERT_EQ(m.positions.size(), 24u * 12u);
  ASSERT_EQ(m.triangles.size(), 2u * 24u * 12u);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const Eigen::Vector3d p = m.positions[i].cast<double>(), n = m.normals[i].cast<double>();
    const double rho = std::hypot(p.x(), p.z());
    // (rho - R)^2 + y^2 = r^2: the implicit torus.
    EXPECT_NEAR((rho - R) * (rho - R) + p.y() * p.y(), r * r, 1e-5);
    EXPECT_NEAR(n.norm(), 1.0, 1e-6);
    // Outward: from the tube's centre circle toward the point.
    const Eigen::Vector3d centre = R * Eigen::Vector3d(p.x() / rho, 0, p.z() / rho);
    EXPECT_GT(n.dot(p - centre), 0.99 * r);
  }
}

TEST(TorusMesh, TrianglesAreCounterClockwiseSeenFromOutside) {
  const Mesh m = torus_mesh();
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    const Eigen::Vector3f face = (b - a).cross(c - a);
    ASSERT_GT(face.norm(), 0.f);
    const Eigen::Vector3f n = m.normals[t[0]] + m.normals[t[1]] + m.normals[t[2]];
    EXPECT_GT(face.dot(n), 0.f);
  }
}

TEST(TorusMesh, BadShapesAreRefused) {
  EXPECT_THROW(torus_mesh(1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(torus_mesh(1.0, 0.4, 2, 12), std::invalid_argument);
  EXPECT_THROW(torus_mesh(1.0, -0.1), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
