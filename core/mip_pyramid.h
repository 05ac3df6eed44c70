// A MIP pyramid of an environment map in its own layout. Each level halves the resolution.
//
// Where the texel grids nest (lat-long and cube with odd sizes, which are "pixel is point";
// octahedral and sphere with even sizes, "pixel is area") a level is the exact solid-angle-weighted
// mean of the finer texels it covers, split by their exact overlaps, so every level has exactly
// the energy sum_p L(p) Omega(p) of level 0 (to rounding). Where they do not nest (a 512-wide
// lat-long) one area-weighted resample (core/resample.h) moves to the nearest nesting size first.
// Lookups blend two levels linearly in the level of detail.
#pragma once

#include "core/env_map.h"

#include <optional>
#include <vector>

namespace rsibr {

class MipPyramid {
 public:
  explicit MipPyramid(const EnvMap& base);

  int levels() const { return int(levels_.size()); }
  const EnvMap& level(int i) const { return levels_.at(std::size_t(i)); }

  // Trilinear lookup: lod 0 is the base; fractional lod blends neighbouring levels; clamped to
  // [0, levels()-1] (NaN reads level 0). Writes channels() floats.
  void sample(const Vec3& dir, double lod, float* out) const;

  // The lod at which one texel subtends about the given solid angle (sr) around dir, i.e.
  // 0.5*log2(omega / omega_texel(level 0)), clamped to >= 0.
  double lod_for_solid_angle(const Vec3& dir, double omega) const;

 private:
  std::vector<EnvMap> levels_;
};

// The next coarser layout whose texels are unions of whole or half texels of this one, if any.
std::optional<Layout> nested_half(const Layout& layout);
// The exact 2:1 reduction onto nested_half(fine.layout) (which must exist).
EnvMap reduce_nested(const EnvMap& fine);

}  // namespace rsibr
