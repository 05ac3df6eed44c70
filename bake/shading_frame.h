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

// A shading basis: the rotation whose columns are (t, b, n), n the unit normal (the local +z that
// bake/brdf.h wants). to_local(world) = [t b n]^T world; to_world is its inverse. Built by
// Frame::around (Duff et al. 2017, "Building an orthonormal basis, revisited"): continuous except
// where n.z changes sign, exact for n = +-z.
class Frame {
 public:
  Frame() = default;  // the identity: around(+z)
  static Frame around(const Vec3& n) {
    const double sign = std::copysign(1.0, n.z());
    const double p = -1.0 / (sign + n.z());
    const double q = n.x() * n.y() * p;
    Mat3 m;
    m.col(0) = Vec3(1.0 + sign * n.x() * n.x() * p, sign * q, -sign * n.x());
    m.col(1) = Vec3(q, sign + n.y() * n.y() * p, -n.y());
    m.col(2) = n;
    return Frame(m);
  }
  Vec3 to_local(const Vec3& world) const { return world_from_local_.transpose() * world; }
  Vec3 to_world(const Vec3& local) const { return world_from_local_ * local; }
  Vec3 normal() const { return world_from_local_.col(2); }
  const Mat3& world_from_local() const { return world_from_local_; }

 private:
  explicit Frame(const Mat3& world_from_local) : world_from_local_(world_from_local) {}
  Mat3 world_from_local_ = Mat3::Identity();
};

// Unit direction from (cos theta, phi) about +z; cos theta is clamped to [-1, 1].
inline Vec3 spherical_direction(double cos_t, double phi) {
  cos_t = std::clamp(cos_t, -1.0, 1.0);
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
  return Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
}

}  // namespace rsibr::shading
