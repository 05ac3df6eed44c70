// Helpers for directions in the local shading frame (n = +z), shared by the BRDFs.
#pragma once

#include "core/vec.h"

#include <algorithm>
#include <cmath>

namespace rsibr::shading {

inline double cos_theta(const Vec3& w) { return w.z(); }

// Mirror reflection of w about the unit axis m: 2 (w.m) m - w.
inline Vec3 reflect(const Vec3& w, const Vec3& m) { return 2.0 * w.dot(m) * m - w; }

// Half vector of wo and wi oriented into the upper hemisphere (h.z >= 0), or 0 when
// wo + wi = 0. Every direction pair related by a reflection about some m with m.z >= 0 has
// m = half_vector_up(wo, wi).
inline Vec3 half_vector_up(const Vec3& wo, const Vec3& wi) {
  Vec3 h = wo + wi;
  const double len = h.norm();
  if (!(len > 0)) return Vec3::Zero();
  h /= len;
  return h.z() < 0 ? Vec3(-h) : h;
}

// Orthonormal basis (columns t, b, a) with third column the unit axis a (Duff et al. 2017,
// "Building an orthonormal basis, revisited"): continuous except across a.z = 0 sign flips,
// exact for a = +-z.
inline Mat3 frame_around(const Vec3& a) {
  const double sign = std::copysign(1.0, a.z());
  const double p = -1.0 / (sign + a.z());
  const double q = a.x() * a.y() * p;
  Mat3 m;
  m.col(0) = Vec3(1.0 + sign * a.x() * a.x() * p, sign * q, -sign * a.x());
  m.col(1) = Vec3(q, sign + a.y() * a.y() * p, -a.y());
  m.col(2) = a;
  return m;
}

// Unit direction from (cos theta, phi) about +z; cos theta is clamped to [-1, 1].
inline Vec3 spherical_direction(double cos_t, double phi) {
  cos_t = std::clamp(cos_t, -1.0, 1.0);
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
  return Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
}

}  // namespace rsibr::shading
