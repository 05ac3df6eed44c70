#include "export/blender_axes.h"

namespace rsibr {

Mat3 blender_from_rsibr() {
  Mat3 p;
  p << 0, 0, 1,  //
      1, 0, 0,   //
      0, 1, 0;
  return p;
}

Mat3 blender_camera_rotation(const Mat3& world_from_cam) {
  // mrcal's camera (y down, z forward) is Blender's camera (y up, z backward) turned half a turn
  // about x.
  return blender_from_rsibr() * world_from_cam * Vec3(1, -1, -1).asDiagonal();
}

}  // namespace rsibr
