// Direction and frame types. Conventions: docs/conventions.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace rsibr {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDeg = kPi / 180;  // radians per degree

// Angle between two (not necessarily unit) vectors, accurate for tiny and near-pi angles
// (acos of a dot product loses half the digits near 0 and pi).
inline double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// world_from_view for a view direction v (world, toward the viewer) and an up hint (world).
// Columns are the view frame's x (right), y (up), z (= v) axes in world coordinates: the
// paper's T. When up is parallel to v, a fixed fallback up is used so the result is always a
// proper rotation (det = +1).
inline Mat3 world_from_view_for(const Vec3& v, const Vec3& up_hint = Vec3(0, 1, 0)) {
  const Vec3 z = v.normalized();
  Vec3 x = up_hint.cross(z);
  if (x.squaredNorm() < 1e-20) {
    // v is (anti)parallel to the hint: pick the world axis least aligned with v.
    const Vec3 alt = std::abs(z.z()) < 0.9 ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    x = alt.cross(z);
  }
  x.normalize();
  const Vec3 y = z.cross(x);
  Mat3 m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = z;
  return m;
}

}  // namespace rsibr
