// A MIP pyramid of an environment map in its own layout: level 0 is the map, each further level
// halves the size (Layout::with_size(kind, size/2)) and is made by the area-weighted resampler
// from the level above, so no level aliases. Stops when the next size would drop below 4 (2 for
// the sphere). Lookups blend two levels linearly in the level of detail.
#pragma once

#include "core/env_map.h"

#include <vector>

namespace rsibr {

class MipPyramid {
 public:
  explicit MipPyramid(const EnvMap& base);

  int levels() const { return int(levels_.size()); }
  const EnvMap& level(int i) const { return levels_.at(std::size_t(i)); }

  // Trilinear lookup: lod 0 is the base; fractional lod blends neighbouring levels; clamped to
  // [0, levels()-1]. Writes channels() floats.
  void sample(const Vec3& dir, double lod, float* out) const;

  // The lod at which one texel subtends about the given solid angle (sr) around dir, i.e.
  // 0.5*log2(omega / omega_texel(level 0)), clamped to >= 0.
  double lod_for_solid_angle(const Vec3& dir, double omega) const;

 private:
  std::vector<EnvMap> levels_;
};

}  // namespace rsibr
