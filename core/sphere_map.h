// Sphere-map coordinates of the paper, as fixed in docs/conventions.md.
//
// (s,t) in [0,1]^2, s to the right, t up. Texel (column c, row r, row 0 at the top) of a W x H
// map has its centre at s = (c+0.5)/W, t = 1 - (r+0.5)/H. With x = 2s-1, y = 2t-1 (the "disc"
// coordinates, unit disc = the sphere's silhouette):
//   g_normal(x,y) = (x, y, sqrt(1-x^2-y^2))                       unit normal, view frame
//   g_mirror(x,y) = (2xz, 2yz, 2z^2-1), (x,y,z) = g_normal(x,y)   mirror direction of the viewer z
//   g_mirror^-1(r) = g_normal^-1((r+z)/|r+z|)                      the half vector (NOT /|r+z|^2)
// Everything here is in the view frame (x right, y up, z toward the viewer).
#pragma once

#include "core/vec.h"

namespace rsibr::sphere_map {

// Disc coordinates (x,y) <-> (s,t).
inline Vec2 disc_from_st(const Vec2& st) { return 2.0 * st - Vec2(1, 1); }
inline Vec2 st_from_disc(const Vec2& xy) { return 0.5 * (xy + Vec2(1, 1)); }

// Continuous pixel position (integer = texel centre, mrcal/OpenEXR style) <-> disc coordinates.
inline Vec2 disc_from_pixel(const Vec2& p, int width, int height) {
  return Vec2((2.0 * p.x() + 1.0) / width - 1.0, 1.0 - (2.0 * p.y() + 1.0) / height);
}
inline Vec2 pixel_from_disc(const Vec2& xy, int width, int height) {
  return Vec2(0.5 * ((xy.x() + 1.0) * width - 1.0), 0.5 * ((1.0 - xy.y()) * height - 1.0));
}

// Unit normal for a disc point; points outside the disc are clamped to the rim (z = 0).
inline Vec3 g_normal(const Vec2& xy) {
  const double rho2 = xy.squaredNorm();
  if (rho2 >= 1.0) {
    const double inv = 1.0 / std::sqrt(rho2);
    return Vec3(xy.x() * inv, xy.y() * inv, 0.0);
  }
  return Vec3(xy.x(), xy.y(), std::sqrt(1.0 - rho2));
}

// Mirror direction (unit) of the viewer direction z about the normal g_normal(xy).
inline Vec3 g_mirror(const Vec2& xy) {
  const Vec3 n = g_normal(xy);
  return Vec3(2 * n.x() * n.z(), 2 * n.y() * n.z(), 2 * n.z() * n.z() - 1.0);
}

// Disc point whose normal is n (n unit, or any length; n.z < 0 is clamped to the rim).
inline Vec2 g_normal_inv(const Vec3& n) {
  const double len = n.norm();
  if (!(len > 0)) return Vec2(0, 0);
  Vec2 xy(n.x() / len, n.y() / len);
  if (n.z() < 0) xy.normalize();  // behind the visible hemisphere: nearest rim point
  return xy;
}

// Disc point whose mirror direction is r (any length). The half vector h = (r+z)/|r+z|;
// for r.z < 0 the term 1 + r.z cancels, so it is computed as (rx^2+ry^2)/(1 - r.z) (|r| = 1).
// r = -z exactly (the singular direction straight behind the sphere) maps to the rim point
// (0,-1), deterministically; every rim point has mirror direction -z.
inline Vec2 g_mirror_inv(const Vec3& r_in) {
  const double len = r_in.norm();
  if (!(len > 0)) return Vec2(0, 0);
  const Vec3 r = r_in / len;
  const double q = r.x() * r.x() + r.y() * r.y();
  const double one_plus_z = r.z() >= 0 ? 1.0 + r.z() : q / (1.0 - r.z());
  const double hlen = std::sqrt(q + one_plus_z * one_plus_z);
  if (!(hlen > 0)) return Vec2(0, -1);
  return Vec2(r.x() / hlen, r.y() / hlen);
}

// Exact area of the intersection of the axis-aligned rectangle [x0,x1] x [y0,y1] with the unit
// disc (closed form, piecewise in x between the points where the disc boundary crosses y0, y1).
double disc_rect_area(double x0, double x1, double y0, double y1);

}  // namespace rsibr::sphere_map
