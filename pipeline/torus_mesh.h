// A built-in mesh for renders when no mesh file is at hand: a torus about +Y (world up), centred
// at the origin, major radius R (centre of the tube from the axis), minor radius r (the tube).
// Every normal direction occurs on it, so a turntable shows the whole lighting.
#pragma once

#include "core/mesh.h"

namespace rsibr {

// segments around the axis, sides around the tube (>= 3 each); r < R. Exact unit normals,
// counter-clockwise triangles seen from outside. Throws std::invalid_argument otherwise.
Mesh torus_mesh(double major_radius = 1.0, double minor_radius = 0.4, int segments = 96, int sides = 48);

}  // namespace rsibr
