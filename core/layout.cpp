#include "core/layout.h"

#include "core/sphere_map.h"

#include <OpenEXR/ImfEnvmap.h>

#include <algorithm>
#include <stdexcept>

namespace rsibr {
namespace {

Imath::V3f to_imath(const Vec3& d) { return Imath::V3f(float(d.x()), float(d.y()), float(d.z())); }
Vec3 from_imath(const Imath::V3f& d) { return Vec3(d.x, d.y, d.z); }

Imath::Box2i data_window(int w, int h) { return Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(w - 1, h - 1)); }

// Inverse of Imf::CubeMap::pixelPosition for a data window starting at (0,0): the position of a
// pixel inside its face. Each face is stored transposed and/or flipped (ImfEnvmap.cpp).
void cube_face_and_position(const Vec2& p, int sof, Imf::CubeMapFace& face, Imath::V2f& pif) {
  int f = int(std::floor((p.y() + 0.5) / sof));
  f = std::clamp(f, 0, 5);
  face = Imf::CubeMapFace(f);
  const double lx = p.x(), ly = p.y() - double(f) * sof, m = sof - 1;
  double px = 0, py = 0;
  switch (face) {
    case Imf::CUBEFACE_POS_X:
      px = m - ly;
      py = lx;
      break;
    case Imf::CUBEFACE_NEG_X:
      px = m - ly;
      py = m - lx;
      break;
    case Imf::CUBEFACE_POS_Y:
      px = lx;
      py = m - ly;
      break;
    case Imf::CUBEFACE_NEG_Y:
      px = lx;
      py = ly;
      break;
    case Imf::CUBEFACE_POS_Z:
      px = m - lx;
      py = m - ly;
      break;
    case Imf::CUBEFACE_NEG_Z:
      px = lx;
      py = m - ly;
      break;
  }
  pif = Imath::V2f(float(px), float(py));
}

// Solid angle subtended by the rectangle [a0,a1] x [b0,b1] on the plane at unit distance:
//   Omega = F(a1,b1) - F(a0,b1) - F(a1,b0) + F(a0,b0),  F(a,b) = atan2(a b, sqrt(1 + a^2 + b^2)).
double plane_rect_solid_angle(double a0, double a1, double b0, double b1) {
  auto F = [](double a, double b) { return std::atan2(a * b, std::sqrt(1 + a * a + b * b)); };
  return F(a1, b1) - F(a0, b1) - F(a1, b0) + F(a0, b0);
}

double sign_nonneg(double x) { return x < 0 ? -1.0 : 1.0; }

}  // namespace

std::string to_string(LayoutKind kind) {
  switch (kind) {
    case LayoutKind::LatLong: return "latlong";
    case LayoutKind::Cube: return "cube";
    case LayoutKind::Octahedral: return "octahedral";
    case LayoutKind::Sphere: return "sphere";
  }
  return "?";
}

LayoutKind parse_layout_kind(const std::string& name) {
  if (name == "latlong" || name == "lat-long" || name == "equirect") return LayoutKind::LatLong;
  if (name == "cube") return LayoutKind::Cube;
  if (name == "octahedral" || name == "octa") return LayoutKind::Octahedral;
  if (name == "sphere" || name == "mirrorball") return LayoutKind::Sphere;
  throw std::invalid_argument("unknown layout '" + name + "' (expected latlong, cube, octahedral or sphere)");
}

Layout::Layout(LayoutKind kind, int width, int height) : kind_(kind), width_(width), height_(height) {
  const std::string what = to_string(kind) + " layout of " + std::to_string(width) + "x" + std::to_string(height);
  if (width < 2 || height < 2 || width > (1 << 16) || height > (1 << 19))
    throw std::invalid_argument(what + ": size out of range");
  if (kind == LayoutKind::Cube && height != 6 * width)
    throw std::invalid_argument(what + ": a cube map must be W x 6W");
  if (kind == LayoutKind::Octahedral && (width != height || width % 2 != 0))
    throw std::invalid_argument(what + ": an octahedral map must be square with an even side");
}

Layout Layout::with_size(LayoutKind kind, int size) {
  switch (kind) {
    case LayoutKind::LatLong: return Layout(kind, size, std::max(2, size / 2));
    case LayoutKind::Cube: return Layout(kind, size, 6 * size);
    case LayoutKind::Octahedral: return Layout(kind, size + (size % 2), size + (size % 2));
    case LayoutKind::Sphere: return Layout(kind, size, size);
  }
  throw std::logic_error("bad layout kind");
}

int Layout::size() const { return kind_ == LayoutKind::LatLong || kind_ == LayoutKind::Cube ? width_ : width_; }

Vec3 octahedral_direction(const Vec2& uv) {
  double u = uv.x(), v = uv.y();
  double x, y, z;
  const double l1 = std::abs(u) + std::abs(v);
  if (l1 <= 1.0) {
    x = u;
    z = -v;
    y = 1.0 - l1;
  } else {  // unfold the corner triangles onto the lower faces
    x = (1.0 - std::abs(v)) * sign_nonneg(u);
    z = -(1.0 - std::abs(u)) * sign_nonneg(v);
    y = 1.0 - l1;  // = -(1 - |x| - |z|)
  }
  return Vec3(x, y, z).normalized();
}

Vec2 octahedral_uv(const Vec3& d) {
  const double l1 = std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z());
  if (!(l1 > 0)) return Vec2(0, 0);
  const double u0 = d.x() / l1, v0 = -d.z() / l1;
  if (d.y() >= 0) return Vec2(u0, v0);
  return Vec2((1.0 - std::abs(v0)) * sign_nonneg(u0), (1.0 - std::abs(u0)) * sign_nonneg(v0));
}

std::optional<Vec3> Layout::direction(const Vec2& p) const {
  switch (kind_) {
    case LayoutKind::LatLong: {
      const Imath::V3f d =
          Imf::LatLongMap::direction(data_window(width_, height_), Imath::V2f(float(p.x()), float(p.y())));
      return from_imath(d).normalized();
    }
    case LayoutKind::Cube: {
      Imf::CubeMapFace face;
      Imath::V2f pif;
      cube_face_and_position(p, width_, face, pif);
      return from_imath(Imf::CubeMap::direction(face, data_window(width_, height_), pif)).normalized();
    }
    case LayoutKind::Octahedral: {
      const Vec2 uv((2.0 * p.x() + 1.0) / width_ - 1.0, 1.0 - (2.0 * p.y() + 1.0) / height_);
      return octahedral_direction(uv.cwiseMax(-1.0).cwiseMin(1.0));
    }
    case LayoutKind::Sphere: {
      // A rim point computed from a direction may land a rounding error outside the disc.
      const Vec2 xy = sphere_map::disc_from_pixel(p, width_, height_);
      if (xy.squaredNorm() > 1.0 + 1e-9) return std::nullopt;
      return sphere_map::g_mirror(xy);
    }
  }
  return std::nullopt;
}

std::optional<Vec3> Layout::texel_direction(int c, int r) const {
  if (auto d = direction(Vec2(c, r))) return d;
  if (kind_ != LayoutKind::Sphere) return std::nullopt;
  const Vec2 centre(0.5 * width_ - 0.5, 0.5 * height_ - 0.5);
  const Vec2 q(std::clamp(centre.x(), c - 0.5, c + 0.5), std::clamp(centre.y(), r - 0.5, r + 0.5));
  return direction(q);
}

Vec2 Layout::pixel(const Vec3& d) const {
  switch (kind_) {
    case LayoutKind::LatLong: {
      const Imath::V2f p = Imf::LatLongMap::pixelPosition(data_window(width_, height_), to_imath(d));
      return Vec2(p.x, p.y);
    }
    case LayoutKind::Cube: {
      const Imath::Box2i dw = data_window(width_, height_);
      Imf::CubeMapFace face;
      Imath::V2f pif;
      Imf::CubeMap::faceAndPixelPosition(to_imath(d), dw, face, pif);
      const Imath::V2f p = Imf::CubeMap::pixelPosition(face, dw, pif);
      return Vec2(p.x, p.y);
    }
    case LayoutKind::Octahedral: {
      const Vec2 uv = octahedral_uv(d);
      return Vec2(0.5 * ((uv.x() + 1.0) * width_ - 1.0), 0.5 * ((1.0 - uv.y()) * height_ - 1.0));
    }
    case LayoutKind::Sphere: return sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(d), width_, height_);
  }
  return Vec2(0, 0);
}

double Layout::texel_solid_angle(int c, int r) const {
  switch (kind_) {
    case LayoutKind::LatLong: {
      // Row r spans latitude [lat_r - h, lat_r + h] clipped to the poles; the two seam columns
      // each own half a column's width.
      const double dlat = kPi / (height_ - 1), dlon = 2 * kPi / (width_ - 1);
      const double lat = 0.5 * kPi - dlat * r;
      const double top = std::min(0.5 * kPi, lat + 0.5 * dlat);
      const double bot = std::max(-0.5 * kPi, lat - 0.5 * dlat);
      const double w = (c == 0 || c == width_ - 1) ? 0.5 : 1.0;
      return (std::sin(top) - std::sin(bot)) * dlon * w;
    }
    case LayoutKind::Cube: {
      const int sof = width_;
      Imf::CubeMapFace face;
      Imath::V2f pif;
      cube_face_and_position(Vec2(c, r), sof, face, pif);
      const double m = sof - 1, s = 2.0 / m;
      auto coord = [&](double q) { return std::clamp(q, 0.0, m) * s - 1.0; };
      return plane_rect_solid_angle(coord(pif.x - 0.5), coord(pif.x + 0.5), coord(pif.y - 0.5), coord(pif.y + 0.5));
    }
    case LayoutKind::Octahedral: {
      // A texel is a square in (u,v). Lines on one octahedron face project to great circles, so
      // a texel lying on one face is an exact spherical quad. With N even the folds u = 0 and
      // v = 0 follow texel edges, and the fold |u|+|v| = 1 runs corner to corner through the
      // texels it meets, cutting them into two triangles, each on one face.
      const int n = width_;
      auto uv_of = [&](int i, int j) { return Vec2(2.0 * i / n - 1.0, 1.0 - 2.0 * j / n); };
      const Vec3 c00 = octahedral_direction(uv_of(c, r)), c10 = octahedral_direction(uv_of(c + 1, r));
      const Vec3 c01 = octahedral_direction(uv_of(c, r + 1)), c11 = octahedral_direction(uv_of(c + 1, r + 1));
      const Vec2 mid = uv_of(c, r) + Vec2(1.0 / n, -1.0 / n);
      const double su = sign_nonneg(mid.x()), sv = sign_nonneg(mid.y());
      // The fold line in this quadrant is su*u + sv*v = 1, i.e. su*(2i-n) + sv*(n-2j) = n.
      auto on_fold = [&](int i, int j) { return su * (2 * i - n) + sv * (n - 2 * j) == n; };
      if (on_fold(c, r) && on_fold(c + 1, r + 1))
        return spherical_triangle_solid_angle(c00, c10, c11) + spherical_triangle_solid_angle(c00, c11, c01);
      return spherical_triangle_solid_angle(c00, c10, c01) + spherical_triangle_solid_angle(c10, c11, c01);
    }
    case LayoutKind::Sphere: {
      // Equal-area: a mirror ball maps disc area to solid angle with d(omega) = 4 dx dy.
      const double x0 = 2.0 * c / width_ - 1.0, x1 = 2.0 * (c + 1) / width_ - 1.0;
      const double y1 = 1.0 - 2.0 * r / height_, y0 = 1.0 - 2.0 * (r + 1) / height_;
      return 4.0 * sphere_map::disc_rect_area(x0, x1, y0, y1);
    }
  }
  return 0.0;
}

double Layout::solid_angle_density(const Vec2& p) const {
  switch (kind_) {
    case LayoutKind::LatLong: {
      const double dlat = kPi / (height_ - 1), dlon = 2 * kPi / (width_ - 1);
      const double lat = 0.5 * kPi - dlat * p.y();
      return std::max(0.0, std::cos(lat)) * dlat * dlon;
    }
    case LayoutKind::Cube: {
      Imf::CubeMapFace face;
      Imath::V2f pif;
      cube_face_and_position(p, width_, face, pif);
      const double s = 2.0 / (width_ - 1);
      const double a = pif.x * s - 1.0, b = pif.y * s - 1.0;
      const double q = 1.0 + a * a + b * b;
      return s * s / (q * std::sqrt(q));
    }
    case LayoutKind::Octahedral: {
      // d(omega) = du dv / |p|^3 with p the point on the octahedron |x|+|y|+|z| = 1.
      const Vec2 uv((2.0 * p.x() + 1.0) / width_ - 1.0, 1.0 - (2.0 * p.y() + 1.0) / height_);
      const double u = std::clamp(uv.x(), -1.0, 1.0), v = std::clamp(uv.y(), -1.0, 1.0);
      double x = u, z = v, y = 1.0 - std::abs(u) - std::abs(v);
      if (y < 0) {
        x = 1.0 - std::abs(v);
        z = 1.0 - std::abs(u);
      }
      const double len = std::sqrt(x * x + y * y + z * z);
      const double s = 2.0 / width_;
      return s * s / (len * len * len);
    }
    case LayoutKind::Sphere: {
      const Vec2 xy = sphere_map::disc_from_pixel(p, width_, height_);
      return xy.squaredNorm() <= 1.0 ? 4.0 * (2.0 / width_) * (2.0 / height_) : 0.0;
    }
  }
  return 0.0;
}

}  // namespace rsibr
