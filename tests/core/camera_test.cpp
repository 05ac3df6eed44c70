#include "core/camera.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

TEST(Camera, LookAtCentrePixelRayHitsTarget) {
  const Camera c = look_at(Vec3(1, 2, 5), Vec3(0.5, 0, -1), Vec3(0, 1, 0), 40, 641, 361);
  const Vec3 d = c.ray_direction(c.cx, c.cy);
  EXPECT_LT(angle_between(d, Vec3(0.5, 0, -1) - Vec3(1, 2, 5)), 1e-12);
  EXPECT_NEAR(c.world_from_cam.determinant(), 1.0, 1e-12);
  EXPECT_GT(c.up().y(), 0.9);  // image up is world up for a near-horizontal view
}

TEST(Camera, ProjectInvertsRayDirection) {
  const Camera c = look_at(Vec3(0, 0, 3), Vec3(0, 0, 0), Vec3(0, 1, 0), 50, 320, 200);
  for (double px : {0.0, 10.25, 319.0})
    for (double py : {0.0, 99.5, 199.0}) {
      Vec2 p;
      ASSERT_TRUE(c.project(c.eye + 2.5 * c.ray_direction(px, py), &p));
      EXPECT_NEAR(p.x(), px, 1e-9);
      EXPECT_NEAR(p.y(), py, 1e-9);
    }
  Vec2 p;
  EXPECT_FALSE(c.project(c.eye - c.forward(), &p));
}

TEST(Camera, VerticalFieldOfViewSpansImageEdges) {
  const Camera c = look_at(Vec3(0, 0, 3), Vec3(0, 0, 0), Vec3(0, 1, 0), 60, 100, 50);
  // Edges of the image (not pixel centres) are at rows -1/2 and H - 1/2.
  EXPECT_NEAR(angle_between(c.ray_direction(c.cx, -0.5), c.ray_direction(c.cx, 49.5)), 60 * kPi / 180, 1e-12);
  // Top of the image is world up.
  EXPECT_GT(c.ray_direction(c.cx, 0).y(), 0);
}

TEST(Camera, FrameBoundsKeepsTheBoundingSphereInView) {
  Eigen::AlignedBox3f box(Eigen::Vector3f(-1, -2, -0.5f), Eigen::Vector3f(3, 1, 0.5f));
  const Camera c = frame_bounds(box, Vec3(0, 0, -1), Vec3(0, 1, 0), 45, 200, 100, 1.0);
  const Vec3 centre = box.center().cast<double>();
  const double radius = 0.5 * box.diagonal().norm();
  // Tangent from the eye to the bounding sphere is exactly the half field of view (vertical, smaller).
  EXPECT_NEAR(std::asin(radius / (c.eye - centre).norm()), 22.5 * kPi / 180, 1e-9);
  for (int i = 0; i < 8; ++i) {
    Vec2 p;
    ASSERT_TRUE(c.project(box.corner(Eigen::AlignedBox3f::CornerType(i)).cast<double>(), &p));
    EXPECT_GE(p.y(), -0.5);
    EXPECT_LE(p.y(), 99.5);
  }
}

TEST(Camera, OrbitFullTurnReturnsToStartAndKeepsDistance) {
  const Camera c = look_at(Vec3(0, 1, 4), Vec3(0, 0, 0), Vec3(0, 1, 0), 40, 64, 64);
  const Camera q = orbit(c, Vec3::Zero(), Vec3(0, 1, 0), 1, 4);
  EXPECT_NEAR((q.eye - Vec3(4, 1, 0)).norm(), 0, 1e-12);  // +90 degrees about +Y takes +Z to +X
  EXPECT_LT(angle_between(q.forward(), -q.eye), 1e-12);
  const Camera full = orbit(c, Vec3::Zero(), Vec3(0, 1, 0), 4, 4);
  EXPECT_EQ(full.eye, c.eye);
}

TEST(Camera, BadInputsAreRejected) {
  EXPECT_THROW(look_at(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 1, 0), 40, 10, 10), std::invalid_argument);
  EXPECT_THROW(look_at(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 180, 10, 10), std::invalid_argument);
  EXPECT_THROW(look_at(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 40, 0, 10), std::invalid_argument);
  // Up parallel to the view still gives a rotation.
  const Camera c = look_at(Vec3(0, 5, 0), Vec3(0, 0, 0), Vec3(0, 1, 0), 40, 10, 10);
  EXPECT_NEAR(c.world_from_cam.determinant(), 1.0, 1e-12);
  EXPECT_EQ(parse_vec3(" 1, -2.5,3e2", "eye"), Vec3(1, -2.5, 300));
  EXPECT_THROW(parse_vec3("1,2", "eye"), std::invalid_argument);
  EXPECT_THROW(parse_vec3("1,2,3,4", "eye"), std::invalid_argument);
  EXPECT_THROW(parse_vec3("1,nan,3", "eye"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
