// Reflection-space warps: where a destination texel's central direction lands in a source map.
//
// Derived from the meaning of a texel (docs/conventions.md), NOT from the paper's printed
// chains: texel p of the map for view v, whose frame is T_v = world_from_view, holds the radiance
// leaving a surface with normal n = T_v g_normal(p) toward a viewer at infinity along v, i.e. with
// mirror direction r = T_v g_mirror(p). A destination texel p_d and a source texel p_s show the same
// thing when their central directions agree in world space, so
//
//   mirror warp:  p_s = g_mirror^-1( T_s^T T_d g_mirror(p_d) )      (mirror-centred BRDFs)
//   normal warp:  p_s = g_normal^-1( T_s^T T_d g_normal(p_d) )      (normal-centred BRDFs)
//
// with g_mirror^-1(r) = g_normal^-1((r + z)/|r + z|) (the half vector; the paper's squared divisor is
// wrong). source_from_dest = T_s^T T_d is the one 3x3 rotation per source and frame.
//
// Singularities (what a source cannot represent), measured by WarpSample::rim, the z component (in
// the source frame) of the source normal at the landing point before clamping to the rim:
//   mirror: rim = h_z = sin(phi/2), phi = angle between r and -v_s. rim -> 0 as r -> -v_s, which the
//           source map smears over its whole rim. rim is in [0, 1].
//   normal: rim = n.v_s. Normals with rim <= 0 face away from v_s and are not in the source map at
//           all (they are clamped to the nearest rim point). rim is in [-1, 1].
// The blend (runtime/blend.h) fades each source's weight to 0 as rim -> 0.
#pragma once

#include "core/central_direction.h"
#include "core/vec.h"

#include <string>
#include <utility>
#include <vector>

namespace rsibr {

// Where one central direction lands in a source map.
struct WarpSample {
  Vec2 disc = Vec2(0, 0);  // source disc coordinates (x right, y up), |disc| <= 1
  double rim = 1;          // see the header comment; <= 0 means the source cannot represent it
};

// The central direction (view frame, unit) of disc point xy: g_mirror or g_normal.
Vec3 central_direction(CentralDirection kind, const Vec2& xy);

// The inverse for a direction expressed in the source's view frame (any length > 0): the source disc
// point and its rim value. Mirror: the disc point is bitwise sphere_map::g_mirror_inv(dir); dir = -z
// exactly gives (0,-1) with rim 0. Normal: sphere_map::g_normal_inv(dir) (nearest rim point for
// dir.z < 0; dir = -z exactly gives (0,-1)). A zero or non-finite dir gives the centre with rim 0.
WarpSample warp_direction(CentralDirection kind, const Vec3& dir_in_source);

// Destination texels of a width x height sphere map whose centre lies inside the unit disc
// (x^2 + y^2 <= 1, the same test core's sphere-map sampling uses): columns [first, second) of `row`;
// empty (first == second) when none.
std::pair<int, int> disc_span(int row, int width, int height);

// Structure-of-arrays forms of the exact warp in single precision, for the blend engine's row loops
// (runtime/blend_engine.h) that the compiler vectorises (no branches, no calls per texel; 8 texels a
// vector with AVX2, 16 with AVX-512, the same bits on every path).
//   central_directions_row: the central directions of `kind` (the destination's own frame) of the
//     destination texels (c, row), c in [c_begin, c_end): out_x/y/z[c - c_begin], the arithmetic of
//     g_normal / g_mirror in float. The texel centres must lie inside the disc (within disc_span).
//   warp_directions: warp_direction for the n unit directions (x, y, z) rotated by m (row-major 3x3,
//     the source_from_dest rotation): the source disc point (disc_x, disc_y) and rim value. The
//     rotated direction is taken as unit (no renormalisation: the input is unit and m a rotation);
//     r = -z exactly (mirror) and a normal straight behind give (0, -1) with rim 0, as warp_direction
//     does. Agrees with warp_direction to float rounding: ~1e-7 in the rim value, ~1e-7 / rim in the
//     disc point near the mirror singularity (tests/runtime/warp_test.cpp).
void central_directions_row(CentralDirection kind, int width, int height, int row, int c_begin, int c_end, float* out_x,
                            float* out_y, float* out_z);
void warp_directions(CentralDirection kind, const float m[9], int n, const float* x, const float* y, const float* z,
                     float* disc_x, float* disc_y, float* rim);

// The interface of the warp implementations (a speed/accuracy knob). Implementations are immutable
// after construction and safe to call from many threads at once.
class Warp {
 public:
  virtual ~Warp() = default;
  virtual const char* name() const = 0;
  // Whether warp_row may be called for a width x height destination.
  virtual bool supports(int width, int height) const { return width > 0 && height > 0; }
  virtual void warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                        int c_begin, int c_end, WarpSample* out) const = 0;
  // The same map in single precision, structure of arrays (the blend engine's form): for texels
  // (c, row), c in [c_begin, c_end), disc_x/disc_y/rim[c - c_begin]. The default converts warp_row's
  // samples; the exact and precomputed warps compute it in vectorised float loops.
  virtual void warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                          int c_begin, int c_end, float* disc_x, float* disc_y, float* rim) const;
  // For a caller that warps one destination into several sources (the blend engine): the central
  // directions (x, y, z)[c - c_begin] that warp_block rotates, so that warp_directions(kind, m, ...) on
  // them gives warp_block's result to the bit, computed once for all sources. False (nothing
  // written) for a warp that does not rotate central directions (the tessellated and
  // double-indirection warps interpolate); the caller then calls warp_block per source.
  virtual bool central_block(CentralDirection kind, int width, int height, int row, int c_begin, int c_end, float* x,
                             float* y, float* z) const;
};

// Per texel, from scratch: disc coordinates, g, rotation, g^-1.
class ExactWarp final : public Warp {
 public:
  const char* name() const override { return "exact"; }
  void warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                int c_end, WarpSample* out) const override;
  // central_directions_row then warp_directions, in blocks of 64 texels on the stack.
  void warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                  int c_end, float* disc_x, float* disc_y, float* rim) const override;
  bool central_block(CentralDirection kind, int width, int height, int row, int c_begin, int c_end, float* x, float* y,
                     float* z) const override;
};

// The destination texels' central directions (g_mirror and g_normal of every texel centre, in the
// destination's own view frame) do not depend on the view, so they are tabulated once for one
// destination size (seed 002's table idea); a frame then costs one 3x3 rotation and one g^-1 per texel
// and source. Results equal ExactWarp's (same arithmetic, read from the table; warp_block reads a
// float table, computed as central_directions_row does, so it equals ExactWarp's warp_block to the
// bit). Throws std::invalid_argument when called for another size than it was built for.
class PrecomputedWarp final : public Warp {
 public:
  PrecomputedWarp(int width, int height);
  const char* name() const override { return "precomputed"; }
  int width() const { return width_; }
  int height() const { return height_; }
  bool supports(int width, int height) const override { return width == width_ && height == height_; }
  void warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                int c_end, WarpSample* out) const override;
  void warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                  int c_end, float* disc_x, float* disc_y, float* rim) const override;
  bool central_block(CentralDirection kind, int width, int height, int row, int c_begin, int c_end, float* x, float* y,
                     float* z) const override;

 private:
  void check_size(int width, int height) const;
  int width_, height_;
  std::vector<Vec3> mirror_;  // row-major, width_ * height_
  std::vector<Vec3> normal_;
  // Single precision, structure of arrays: planes x, y, z of the mirror, then of the normal
  // directions, each row-major width_ * height_ (0 outside the disc).
  std::vector<float> planes_;
};

}  // namespace rsibr
