#include "core/resolution_mask.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

double native_detail_level(const MapView& v) {
  double native = v.rgb.cols;
  if (const auto it = v.attributes.find("nativeSize"); it != v.attributes.end()) {
    std::size_t used = 0;
    try {
      native = std::stod(it->second, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != it->second.size() || !(native > 0) || !std::isfinite(native))
      throw std::invalid_argument("rsibr.nativeSize '" + it->second + "' is not a positive number of texels");
  }
  return native < v.rgb.cols ? std::log2(double(v.rgb.cols) / native) : 0.0;
}

bool mixed_resolution(const std::vector<double>& levels) {
  if (levels.empty()) return false;
  const auto [lo, hi] = std::minmax_element(levels.begin(), levels.end());
  return *hi - *lo > 0.5;
}

std::unique_ptr<MaskPyramid> resolution_mask(const cv::Mat& coverage_in, double detail_level) {
  if (coverage_in.type() != CV_32FC1 || coverage_in.empty())
    throw std::invalid_argument("resolution mask: the coverage must be a non-empty CV_32FC1 image");
  cv::Mat coverage;
  cv::min(cv::max(coverage_in, 0.0), 1.0, coverage);
  cv::patchNaNs(coverage, 0.0);
  const int W = coverage.cols, H = coverage.rows;
  return std::make_unique<MaskPyramid>(W, H, [&](int level, int col, int row) {
    double lo = 0;
    cv::minMaxLoc(coverage(MaskPyramid::footprint(W, H, level, col, row)), &lo);
    return float(lo * std::clamp(double(level) - detail_level + 1.0, 0.0, 1.0));
  });
}

}  // namespace rsibr
