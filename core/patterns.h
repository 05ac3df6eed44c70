// Analytic environments: known radiance as a function of direction, rendered into any layout.
// Used by tests (exact integrals), benchmarks and the figures in docs/.
#pragma once

#include "core/env_map.h"

#include <functional>

namespace rsibr {

using Radiance = std::function<Vec3(const Vec3& unit_dir)>;  // L_i(w), linear RGB

// Renders f into the layout: each texel is the solid-angle-weighted mean of f over its cell,
// from an m x m grid of points (m = subsamples), or f at the centre when m = 1. Texels outside a
// sphere map's disc are 0.
EnvMap render_pattern(const Radiance& f, const Layout& layout, int subsamples = 4);

namespace patterns {

Radiance constant(const Vec3& rgb);
// RGB = (d + 1) / 2: every direction has its own colour; integral 2*pi per channel.
Radiance direction_coded();
// A checker of squares `degrees` wide in latitude and longitude (values lo and hi).
Radiance latlong_checker(double degrees, double lo = 0.0, double hi = 1.0);
// Sky: a smooth gradient from horizon_rgb (at and below the horizon) to zenith_rgb, plus a disc
// sun of angular radius sun_radius (rad) and radiance sun_rgb centred on sun_dir.
Radiance sun_and_sky(const Vec3& sun_dir, double sun_radius, const Vec3& sun_rgb, const Vec3& zenith_rgb,
                     const Vec3& horizon_rgb);

}  // namespace patterns
}  // namespace rsibr
