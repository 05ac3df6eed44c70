// rsibr's world and Blender's. rsibr's is right-handed and +Y up (docs/conventions.md); Blender's
// is right-handed and +Z up. The equirectangular image that rsibr writes for Blender
// (core/cell_centred_latlong.h) is read by Blender's Environment Texture so that rsibr's direction
// (x, y, z) is Blender's (z, x, y): one proper rotation that maps every point, direction and
// frame of an rsibr run into Blender unchanged otherwise (no mirror, no scale).
#pragma once

#include "core/vec.h"

namespace rsibr {

// blender = blender_from_rsibr() * rsibr, for points and directions.
Mat3 blender_from_rsibr();

// A Blender camera's rotation (columns: its local x right, y up, z backward, in Blender's world)
// from rsibr's world_from_cam (columns: the camera's x right, y down, z forward, in rsibr's world).
Mat3 blender_camera_rotation(const Mat3& world_from_cam);

}  // namespace rsibr
