// Exact area-weighted resizing of a lat-long map to another lat-long size.
//
// A lat-long texel ("pixel is point", core/layout.h) is a longitude interval times a latitude
// interval, and its solid angle is the product of the longitude length and the difference of the
// sines of its latitudes. So the solid-angle-weighted mean of the source's (piecewise-constant)
// texels over an output texel is separable: longitudes weighted by overlap length, then rows
// weighted by overlap in sin(latitude). Every output texel is that exact mean, so
// sum L Omega is kept to rounding, at a cost linear in the texels (rows and columns threaded).
#pragma once

#include "core/env_map.h"

namespace rsibr {

// src: lat-long, CV_32F, any channels; width >= 2, height >= 2.
EnvMap latlong_area_resize(const EnvMap& src, int width, int height);

}  // namespace rsibr
