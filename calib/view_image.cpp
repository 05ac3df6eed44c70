#include "calib/view_image.h"

#include "core/exr_io.h"
#include "core/input_file.h"
#include "core/safe_name.h"
#include "core/truth_image.h"
#include "hdr/merged_exr.h"

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <Eigen/Dense>

#include <filesystem>
#include <stdexcept>

namespace rsibr {

ViewImage read_view_image(const std::string& path) {
  require_regular_file(path);
  ViewImage v;
  try {
    const MergedImage m = read_merged_exr(path);
    v.radiance = m.radiance;
    v.flags = m.flags;
    v.merged = true;
  } catch (const std::exception&) {
    cv::Mat img = read_truth_image(path);  // throws "<path>: ..." for anything but float R, G, B (or Y)
    if (img.type() != CV_32FC3) throw std::runtime_error(path + ": expected R, G, B channels");
    v.radiance = img;
  }
  try {
    check_exr_before_reading(path);
    Imf::InputFile file(path.c_str());
    if (const auto* a = file.header().findTypedAttribute<Imf::StringAttribute>("rsibr.view")) v.name = a->value();
    if (const auto* a = file.header().findTypedAttribute<Imf::M33fAttribute>("rsibr.worldFromCam")) {
      Mat3 m;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m(r, c) = a->value()[r][c];
      // A rotation to float precision; re-orthonormalised so frames built from it stay proper.
      Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Mat3 rot = svd.matrixU() * svd.matrixV().transpose();
      if (!rot.allFinite() || rot.determinant() < 0.5 || (rot - m).norm() > 1e-3)
        throw std::runtime_error(path + ": rsibr.worldFromCam is not a rotation");
      v.world_from_cam = rot;
    }
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  if (!v.name.empty()) require_safe_name(v.name, path + ": rsibr.view");  // the name goes into pose files
  return v;
}

}  // namespace rsibr
