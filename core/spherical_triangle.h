// Spherical-triangle measures shared by layouts, view sets and tests.
#pragma once

#include "core/vec.h"

namespace rsibr {

// Solid angle of the spherical triangle with unit vertices a, b, c (Van Oosterom & Strackee):
//   tan(Omega/2) = |a.(b x c)| / (1 + a.b + b.c + c.a),
// exact for degenerate triangles (0) and stable for tiny ones.
// The numerator uses edge differences, a.((b-a) x (c-a)) = a.(b x c), which keeps full relative
// precision for triangles with edges down to ~1e-8 rad (the plain triple product loses it).
inline double spherical_triangle_solid_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double num = std::abs(a.dot((b - a).cross(c - a)));
  const double den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
  return 2.0 * std::atan2(num, den);
}

}  // namespace rsibr
