#include "runtime/warp.h"

#include "core/sphere_map.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

WarpKind warp_kind_from_string(const std::string& name) {
  if (name == "mirror") return WarpKind::Mirror;
  if (name == "normal") return WarpKind::Normal;
  throw std::invalid_argument("warp: unknown warp '" + name + "' (expected mirror or normal)");
}

const char* to_string(WarpKind kind) { return kind == WarpKind::Mirror ? "mirror" : "normal"; }

Vec3 central_direction(WarpKind kind, const Vec2& xy) {
  return kind == WarpKind::Mirror ? sphere_map::g_mirror(xy) : sphere_map::g_normal(xy);
}

// g_mirror^-1 with the half vector's z as the rim value:
//   h = (r + z)/|r + z|,  disc = (h_x, h_y),  rim = h_z = sin(phi/2), phi = angle(r, -z).
// 1 + r_z cancels for r_z < 0, so it is computed as (r_x^2 + r_y^2)/(1 - r_z) (|r| = 1); the same
// operations as sphere_map::g_mirror_inv, so the disc point is bitwise equal to it.
static inline WarpSample mirror_inverse(const Vec3& r_in) {
  const double len = r_in.norm();
  if (!(len > 0) || !std::isfinite(len)) return {Vec2(0, 0), 0.0};
  const Vec3 r = r_in / len;
  const double q = r.x() * r.x() + r.y() * r.y();
  const double one_plus_z = r.z() >= 0 ? 1.0 + r.z() : q / (1.0 - r.z());
  const double hlen = std::sqrt(q + one_plus_z * one_plus_z);
  if (!(hlen > 0)) return {Vec2(0, -1), 0.0};  // r = -z exactly: the singular direction
  return {Vec2(r.x() / hlen, r.y() / hlen), one_plus_z / hlen};
}

// g_normal^-1 with n.z/|n| as the rim value; n.z < 0 goes to the nearest rim point.
static inline WarpSample normal_inverse(const Vec3& n) {
  const double len = n.norm();
  if (!(len > 0) || !std::isfinite(len)) return {Vec2(0, 0), 0.0};
  Vec2 xy(n.x() / len, n.y() / len);
  const double rim = n.z() / len;
  if (n.z() < 0) {
    const double l2 = xy.squaredNorm();
    xy = l2 > 0 ? Vec2(xy / std::sqrt(l2)) : Vec2(0, -1);  // straight behind: a fixed rim point
  }
  return {xy, rim};
}

WarpSample warp_direction(WarpKind kind, const Vec3& dir_in_source) {
  return kind == WarpKind::Mirror ? mirror_inverse(dir_in_source) : normal_inverse(dir_in_source);
}

std::pair<int, int> disc_span(int row, int width, int height) {
  const auto inside = [&](int c) { return sphere_map::disc_from_pixel(Vec2(c, row), width, height).squaredNorm() <= 1.0; };
  int c0 = 0, c1 = width;
  while (c0 < width && !inside(c0)) ++c0;
  if (c0 == width) return {0, 0};
  while (c1 > c0 && !inside(c1 - 1)) --c1;
  return {c0, c1};
}

void ExactWarp::warp_row(WarpKind kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                         int c_end, WarpSample* out) const {
  for (int c = c_begin; c < c_end; ++c) {
    const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, row), width, height);
    out[c - c_begin] = warp_direction(kind, source_from_dest * central_direction(kind, xy));
  }
}

PrecomputedWarp::PrecomputedWarp(int width, int height) : width_(width), height_(height) {
  if (width < 1 || height < 1) throw std::invalid_argument("PrecomputedWarp: size must be positive");
  mirror_.resize(std::size_t(width) * std::size_t(height));
  normal_.resize(mirror_.size());
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
      const std::size_t i = std::size_t(r) * std::size_t(width) + std::size_t(c);
      mirror_[i] = sphere_map::g_mirror(xy);
      normal_[i] = sphere_map::g_normal(xy);
    }
}

void PrecomputedWarp::warp_row(WarpKind kind, const Mat3& source_from_dest, int width, int height, int row,
                               int c_begin, int c_end, WarpSample* out) const {
  if (width != width_ || height != height_)
    throw std::invalid_argument("PrecomputedWarp: built for " + std::to_string(width_) + "x" + std::to_string(height_) +
                                ", asked for " + std::to_string(width) + "x" + std::to_string(height));
  const Vec3* table = (kind == WarpKind::Mirror ? mirror_.data() : normal_.data()) + std::size_t(row) * std::size_t(width);
  if (kind == WarpKind::Mirror) {
    for (int c = c_begin; c < c_end; ++c) out[c - c_begin] = mirror_inverse(source_from_dest * table[c]);
  } else {
    for (int c = c_begin; c < c_end; ++c) out[c - c_begin] = normal_inverse(source_from_dest * table[c]);
  }
}

}  // namespace rsibr
