// The sizes rsibr process uses when the user gives none: sphere maps and the probe as sharp as the
// photos, so a large ball is not thrown away on a small map (a size the user gives always wins).
//
//   map (chrome)    N = 2r texels a side for a ball of r pixels: one texel per photo pixel across
//                   the ball's disc; a multiple of 16 in [64, 2048]
//   map (grey)      the same, at most 128: Lambert radiance is smooth (its spherical harmonics past
//                   order 2 hold about 1% of it), so a larger map only costs bake time
//   map (glossy)    the same, at most 256 (a highlight is sharper than Lambert shading)
//   probe width     W = pi N / 2 for the largest chrome map: a chrome map's centre texel spans 4 / N
//                   radians of reflection directions and a lat-long texel 2 pi / W; a multiple of
//                   64 in [256, 4096]
//
// Memory: a map texel holds RGB, confidence and clipped (20 bytes); a probe texel RGB, weight,
// clipped, lower bound and flags (36 bytes); memory_bytes states what a step holds at once.
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/lens_model.h"
#include "formats/photo_set.h"

#include <cstddef>

namespace rsibr {

// The ball's outline radius in pixels: the angle its cone subtends, seen through the lens at the
// ball's centre (the mean distance from the centre's pixel to four limb points').
double ball_pixel_radius(const BallCone& cone, const LensModel& lens);

// Sizes for a ball of `radius_px` (the largest over the views) of the given kind.
int default_map_size(BallKind kind, double radius_px);
int default_probe_width(int chrome_map_size);

// Bytes held by `views` maps of size n and by a probe of width w.
std::size_t map_set_bytes(int n, std::size_t views);
std::size_t probe_bytes(int width);

}  // namespace rsibr
