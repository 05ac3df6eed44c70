#include "calib/lens/far_camera.h"

#include "hdr/merge.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rsibr {

bool fills_frame(double radius_px, int width, int height) {
  return std::isfinite(radius_px) && width > 0 && height > 0 &&
         2 * radius_px >= kCropFillFraction * double(std::min(width, height));
}

LensModel far_camera_lens(const std::vector<std::pair<int, int>>& sizes) {
  if (sizes.empty()) throw std::invalid_argument("far camera: no views");
  int w = 0, h = 0;
  for (const auto& [sw, sh] : sizes) {
    if (!(sw > 0 && sh > 0)) throw std::invalid_argument("far camera: a view has no pixels");
    w = std::max(w, sw), h = std::max(h, sh);
  }
  return LensModel::pinhole(kFarCameraFocalPerSide * double(std::max(w, h)), w, h);
}

bool is_far_camera(const LensModel& lens) {
  const std::vector<double>& in = lens.intrinsics();
  const double f = kFarCameraFocalPerSide * double(std::max(lens.width(), lens.height()));
  return lens.name() == "LENSMODEL_PINHOLE" && in.size() == 4 && std::abs(in[0] - f) <= 1e-6 * f &&
         std::abs(in[1] - f) <= 1e-6 * f;
}

ViewImage on_lens_canvas(ViewImage view, const LensModel& lens, const std::string& name) {
  const int w = view.radiance.cols, h = view.radiance.rows;
  if (w == lens.width() && h == lens.height()) return view;
  if (w > lens.width() || h > lens.height())
    throw std::invalid_argument(name + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                " is larger than the lens model's " + std::to_string(lens.width()) + "x" +
                                std::to_string(lens.height()));
  const int right = lens.width() - w, bottom = lens.height() - h;
  cv::copyMakeBorder(view.radiance, view.radiance, 0, bottom, 0, right, cv::BORDER_REPLICATE);
  if (view.flags.empty()) view.flags = cv::Mat::zeros(h, w, CV_8UC1);
  cv::copyMakeBorder(view.flags, view.flags, 0, bottom, 0, right, cv::BORDER_CONSTANT, cv::Scalar(kOutside));
  return view;
}

}  // namespace rsibr
