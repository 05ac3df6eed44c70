// A piecewise-constant 2D distribution over the texels of a lat-long environment, for importance
// sampling the lighting (the environment half of the MIS integrator).
//
// Texel weight:  w(p) = lum(max(0, L(p))) * Omega(p)     (lum: Rec.709 luminance; NaN -> 0)
// Probability:   P(p) = w(p) / sum w; rows by a marginal CDF, columns by conditional CDFs.
// Within a texel the direction is uniform in solid angle over the texel's cell (the cells of
// Layout::texel_solid_angle: rows span [lat - h, lat + h] clipped to the poles, seam columns half
// a column), so the density in solid angle is exactly
//   pdf(w) = P(texel(w)) / Omega(texel(w)).
// An environment with no positive texel falls back to P(p) proportional to Omega(p) (uniform on
// the sphere). Every texel with a positive channel has P > 0.
#pragma once

#include "core/env_map.h"

#include <vector>

namespace rsibr {

class EnvironmentDistribution {
 public:
  // env must be lat-long (throws std::invalid_argument otherwise).
  explicit EnvironmentDistribution(const EnvMap& env);

  struct Sample {
    Vec3 dir = Vec3::Zero();  // world, unit
    long texel = -1;          // r * width + c
    double pdf = 0;           // solid angle
  };
  // u in [0,1)^2; deterministic.
  Sample sample(const Vec2& u) const;
  // Solid-angle density of sample() at dir (any non-zero vector).
  double pdf(const Vec3& dir) const;

  // The point of texel's cell at fractions f in [0,1]^2 (f.x along sin(latitude) from the cell's
  // lower edge, f.y along longitude): uniform f gives points uniform in solid angle.
  Vec3 cell_direction(long texel, const Vec2& f) const;

  // The texel whose cell contains dir (r * width + c).
  long texel_of(const Vec3& dir) const;
  // Solid-angle density of sample() anywhere in that texel's cell.
  double texel_pdf(long texel) const { return density_[std::size_t(texel)]; }
  double probability(long texel) const { return density_[std::size_t(texel)] * solid_angle(texel); }
  double solid_angle(long texel) const {
    const long c = texel % w_;
    return row_omega_[std::size_t(texel / w_)] * (c == 0 || c == w_ - 1 ? 0.5 : 1.0);
  }
  const Layout& layout() const { return layout_; }

 private:
  Layout layout_;
  int w_ = 0, h_ = 0;
  std::vector<double> row_omega_;    // a full column's texel solid angle per row
  std::vector<double> density_;      // per texel: probability / solid angle
  std::vector<double> marginal_;     // h+1 entries, CDF over rows
  std::vector<double> conditional_;  // h rows x (w+1) entries, CDF over columns per row
};

// The cell geometry behind EnvironmentDistribution::cell_direction, for any lat-long layout.
Vec3 latlong_cell_direction(const Layout& latlong, long texel, const Vec2& f);

}  // namespace rsibr
