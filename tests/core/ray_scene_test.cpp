#include "core/ray_scene.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

// A unit square in z = 0 (two CCW triangles seen from +z) with normals tilted toward +x.
Mesh square() {
  Mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const Eigen::Vector3f n = Eigen::Vector3f(0.3f, 0, 1).normalized();
  m.normals = {n, n, n, n};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(RayScene, HitDistancePositionAndNormalsAreExact) {
  const Mesh m = square();
  const RayScene scene(m);
  const RayHit h = scene.intersect(Vec3(0.25, -0.5, 2), Vec3(0, 0, -1));
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 2.0, 1e-6);
  EXPECT_NEAR((scene.position(h) - Vec3(0.25, -0.5, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((scene.geometric_normal(h) - Vec3(0, 0, 1)).norm(), 0, 1e-12);
  EXPECT_NEAR((scene.shading_normal(h) - Vec3(0.3, 0, 1).normalized()).norm(), 0, 1e-6);
}

TEST(RayScene, BackFacesAreHitAndMissesAreReported) {
  const Mesh m = square();
  const RayScene scene(m);
  EXPECT_TRUE(scene.intersect(Vec3(0, 0, -1), Vec3(0, 0, 1)).hit);
  EXPECT_FALSE(scene.intersect(Vec3(3, 0, 1), Vec3(0, 0, -1)).hit);
  EXPECT_FALSE(scene.intersect(Vec3(0, 0, 1), Vec3(0, 0, 1)).hit);
}

TEST(RayScene, OcclusionRespectsTheInterval) {
  const Mesh m = square();
  const RayScene scene(m);
  EXPECT_TRUE(scene.occluded(Vec3(0, 0, 1), Vec3(0, 0, -1)));
  EXPECT_FALSE(scene.occluded(Vec3(0, 0, 1), Vec3(0, 0, -1), 0, 0.5));
  EXPECT_FALSE(scene.occluded(Vec3(0, 0, 1), Vec3(0, 0, -1), 1.5));
}

TEST(RayScene, SharedEdgeIsNeverMissed) {
  const Mesh m = square();
  const RayScene scene(m);
  // Rays straight through the diagonal shared by both triangles.
  for (int i = 0; i <= 100; ++i) {
    const double s = -0.99 + 1.98 * i / 100.0;
    EXPECT_TRUE(scene.intersect(Vec3(s, s, 1), Vec3(0, 0, -1)).hit) << s;
  }
}

}  // namespace
}  // namespace rsibr
