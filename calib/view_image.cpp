#include "calib/view_image.h"

#include "formats/exr_file.h"
#include "core/safe_name.h"
#include "hdr/merged_exr.h"

#include <Eigen/Dense>

namespace rsibr {

ViewImage read_view_image(const std::string& path) {
  // The kind of view is read from the file's channels, not found by trying readers in turn.
  const ExrFileIn file(path);
  const ExrPartIn& h = file.parts().front();
  ViewImage v;
  if (is_merged_view(h)) {
    const MergedImage m = read_merged_exr(file, nullptr, false);  // no variance: calibration does not use it
    v.radiance = m.radiance;
    v.flags = m.flags;
    v.merged = true;
  } else if (h.has_channel("R") && h.has_channel("G") && h.has_channel("B")) {
    v.radiance = file.read(0, {"R", "G", "B"});
  } else {
    throw FileError(path, "expected R, G, B channels (a merged view or a float RGB image); it has: " + h.channel_types);
  }
  if (const auto name = h.get<std::string>("rsibr.view")) v.name = *name;
  if (const auto m = h.get<Mat3>("rsibr.worldFromCam")) {
    // A rotation to float precision; re-orthonormalised so frames built from it stay proper.
    Eigen::JacobiSVD<Mat3> svd(*m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 rot = svd.matrixU() * svd.matrixV().transpose();
    if (!rot.allFinite() || rot.determinant() < 0.5 || (rot - *m).norm() > 1e-3)
      throw FileError(path, "rsibr.worldFromCam is not a rotation");
    v.world_from_cam = rot;
  }
  if (!v.name.empty()) require_safe_name(v.name, path + ": rsibr.view");  // the name goes into pose files
  return v;
}

}  // namespace rsibr
