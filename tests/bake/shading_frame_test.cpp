#include "bake/shading_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rsibr {
namespace {

std::vector<Vec3> normals() {
  std::vector<Vec3> n = {Vec3(0, 0, 1),
                         Vec3(0, 0, -1),
                         Vec3(1, 0, 0),
                         Vec3(0, -1, 0),
                         Vec3(1e-9, 0, -1).normalized(),
                         Vec3(0, 1e-9, 1).normalized(),
                         Vec3(0.3, -0.2, std::nextafter(0.0, 1.0)).normalized(),
                         Vec3(0.3, -0.2, -std::nextafter(0.0, 1.0)).normalized()};
  for (int i = 0; i < 200; ++i) {  // a Fibonacci sphere
    const double z = 1 - (i + 0.5) / 100.0, phi = i * 2.399963229728653;
    const double s = std::sqrt(1 - z * z);
    n.emplace_back(s * std::cos(phi), s * std::sin(phi), z);
  }
  return n;
}

TEST(ShadingFrame, IsAProperRotationWhoseThirdAxisIsTheNormalForEveryNormal) {
  for (const Vec3& n : normals()) {
    const shading::Frame f = shading::Frame::around(n);
    const Mat3& m = f.world_from_local();
    EXPECT_LT((m.transpose() * m - Mat3::Identity()).norm(), 1e-14) << n.transpose();
    EXPECT_NEAR(m.determinant(), 1.0, 1e-14) << n.transpose();
    EXPECT_EQ(f.normal(), n);
    EXPECT_LT((f.to_local(n) - Vec3::UnitZ()).norm(), 1e-15) << n.transpose();
  }
}

TEST(ShadingFrame, ToWorldUndoesToLocal) {
  const Vec3 w = Vec3(0.2, -0.7, 0.4).normalized();
  for (const Vec3& n : normals()) {
    const shading::Frame f = shading::Frame::around(n);
    EXPECT_LT((f.to_world(f.to_local(w)) - w).norm(), 1e-15) << n.transpose();
    EXPECT_NEAR(f.to_local(w).z(), n.dot(w), 1e-15);  // the local z is the cosine to the normal
  }
}

TEST(ShadingFrame, AroundPlusZAndTheDefaultAreTheIdentity) {
  EXPECT_EQ(shading::Frame::around(Vec3::UnitZ()).world_from_local(), Mat3::Identity());
  EXPECT_EQ(shading::Frame().world_from_local(), Mat3::Identity());
  // Around -z: a proper rotation with z reversed (x kept, y flipped), exactly.
  const Mat3 m = shading::Frame::around(-Vec3::UnitZ()).world_from_local();
  EXPECT_EQ(m, Vec3(1, -1, -1).asDiagonal().toDenseMatrix());
}

}  // namespace
}  // namespace rsibr
