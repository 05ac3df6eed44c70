// A sphere as a triangle mesh (latitude rings by longitude segments, poles on +-Y), outward unit
// normals, counter-clockwise seen from outside (core/mesh.h): the balls when a viewer has no mesh.
#pragma once

#include "core/mesh.h"

namespace rsibr {

// Centre `centre`, radius > 0, rings >= 2, segments >= 3; std::invalid_argument otherwise.
Mesh sphere_mesh(const Eigen::Vector3f& centre, float radius, int rings = 64, int segments = 128);

}  // namespace rsibr
