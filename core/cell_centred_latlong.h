// Lat-long images in the cell-centred convention of other programs (Blender's Environment
// Texture, Cycles, Poly Haven's files as their authors made them, pbrt): the same equirectangular
// picture, but its texels sit half a texel further in than rsibr's.
//
// rsibr (OpenEXR's ImfEnvmap, docs/conventions.md): texel centre (x, y) of a W x H map is at
//   longitude pi (1 - 2x/(W-1)), latitude pi/2 - pi y/(H-1)  (columns 0 and W-1 on the seam,
//   rows 0 and H-1 on the poles).
// Cell-centred: texel (i, j) is at longitude pi (1 - 2(i+0.5)/W), latitude pi/2 - pi (j+0.5)/H.
// Both put longitude 0 at +Z and +pi/2 at +X, latitude +pi/2 at +Y. Handing one program's file to
// the other unchanged stretches the sphere by one texel in each direction: a Lambert ball changes
// by +-0.1% radially, a sharp highlight moves by half a texel (docs/blender.md).
#pragma once

#include "core/env_map.h"

namespace rsibr {

// World direction (unit) of the cell-centred texel (i, j) of a W x H lat-long image.
Vec3 cell_centred_latlong_direction(double i, double j, int width, int height);

// The radiance of `env` (any layout) as a width x height cell-centred lat-long image: each texel
// is env's bilinear sample (sample_bilinear) at that texel's direction. For a lat-long env of the
// same size this is an exact bilinear resampling along rows and columns.
EnvMap to_cell_centred_latlong(const EnvMap& env, int width, int height);

}  // namespace rsibr
