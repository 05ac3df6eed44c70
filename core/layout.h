// Environment-map layouts with exact direction <-> pixel mappings (docs/conventions.md).
//
// Pixel positions are continuous with integers at texel centres: texel (column c, row r) has
// centre (c, r) and covers [c-1/2, c+1/2] x [r-1/2, r+1/2] (mrcal's and OpenEXR's convention).
// Directions are in the world frame (+Y up) and need not be unit on input; outputs are unit.
//
//  lat-long    OpenEXR ImfEnvmap LatLongMap: pixel (0,0) is latitude +pi/2, longitude +pi; the
//              first and last columns both lie on the seam (longitude +-pi) and the first and last
//              rows on the poles ("pixel is point"). W x H, any W, H >= 2.
//  cube        OpenEXR ImfEnvmap CubeMap: faces +X,-X,+Y,-Y,+Z,-Z stacked vertically, W x 6W;
//              edge texels of a face lie on the cube's edges ("pixel is point").
//  octahedral  square N x N, N even (seed 004, square form): +Y at the centre, the upper
//              hemisphere in the inner diamond, the lower one folded into the corners;
//              image right = +X, image up = -Z. Texel centres at (c+1/2)/N ("pixel is area").
//  sphere      an orthographic mirror ball seen from +Z: texel p holds direction g_mirror(p)
//              (core/sphere_map.h); texels outside the unit disc carry no direction.
#pragma once

#include "core/spherical_triangle.h"
#include "core/vec.h"

#include <optional>
#include <string>

namespace rsibr {

enum class LayoutKind { LatLong, Cube, Octahedral, Sphere };

std::string to_string(LayoutKind kind);
// Parses "latlong", "cube", "octahedral", "sphere" (also "octa", "mirrorball"); throws otherwise.
LayoutKind parse_layout_kind(const std::string& name);

class Layout {
 public:
  Layout() = default;
  Layout(LayoutKind kind, int width, int height);  // validates the size for the kind

  // Conventional shapes from one size parameter: lat-long size x size/2, cube size x 6*size,
  // octahedral and sphere size x size.
  static Layout with_size(LayoutKind kind, int size);

  LayoutKind kind() const { return kind_; }
  int width() const { return width_; }
  int height() const { return height_; }
  long texel_count() const { return long(width_) * height_; }
  // The one-number size used by with_size (lat-long width, cube face size, square side).
  int size() const;

  // Direction of a continuous pixel position; nullopt only for the sphere layout outside the
  // unit disc. Positions slightly outside the image extrapolate smoothly (used by footprint
  // estimates).
  std::optional<Vec3> direction(const Vec2& pixel) const;
  // A direction representing texel (c, r): its centre's, or for a sphere-map texel whose centre is
  // outside the disc but whose cell is not, the direction of the cell's point nearest the disc's
  // centre. nullopt only for texels with no solid angle.
  std::optional<Vec3> texel_direction(int c, int r) const;
  // Pixel position of a direction; defined for every non-zero direction. For the sphere layout
  // -Z (behind the ball) maps to a rim point.
  Vec2 pixel(const Vec3& dir) const;

  // Solid angle (sr) of texel (c, r): the texels partition the sphere, so the sum over the image is
  // 4*pi up to rounding (exact closed forms per layout; see layout.cpp).
  double texel_solid_angle(int c, int r) const;
  // Solid angle per unit pixel area at a position (0 outside the sphere layout's disc).
  double solid_angle_density(const Vec2& pixel) const;

  bool operator==(const Layout& o) const { return kind_ == o.kind_ && width_ == o.width_ && height_ == o.height_; }

 private:
  LayoutKind kind_ = LayoutKind::LatLong;
  int width_ = 0;
  int height_ = 0;
};

// Octahedral square coordinates (u,v) in [-1,1]^2 (v up) <-> unit direction (world).
Vec3 octahedral_direction(const Vec2& uv);
Vec2 octahedral_uv(const Vec3& dir);

}  // namespace rsibr
