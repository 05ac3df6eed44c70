#include "core/latlong_ripmap.h"

#include "core/latlong_area_resize.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

LatLongRipmap::LatLongRipmap(const EnvMap& src) {
  if (src.layout.kind() != LayoutKind::LatLong || src.pixels.depth() != CV_32F)
    throw std::logic_error("LatLongRipmap: a float lat-long map is required");
  levels_.push_back(src.pixels);
  inverse_scale_.push_back(1.0);
  const int W = src.layout.width();
  for (int j = 1;; ++j) {
    const int w = int(std::ceil(double(W - 1) / double(1L << std::min(j, 40)))) + 1;
    const cv::Mat& prev = levels_.back();
    if (w >= prev.cols || prev.cols <= 3) break;
    // Same rows: the latitude pass keeps them as they are.
    const EnvMap coarser =
        latlong_area_resize(EnvMap{Layout(LayoutKind::LatLong, prev.cols, prev.rows), prev, {}}, w, prev.rows);
    levels_.push_back(coarser.pixels);
    inverse_scale_.push_back(double(w - 1) / double(W - 1));
  }
}

double LatLongRipmap::latitude_step() const { return kPi / (height() - 1); }
double LatLongRipmap::longitude_step(int j) const { return 2 * kPi / (width(j) - 1); }

int LatLongRipmap::level_for_latitude(double phi) const {
  const double across = std::abs(std::cos(phi)), dlat = latitude_step();
  int j = 0;
  while (j + 1 < levels() && longitude_step(j + 1) * across <= dlat) ++j;
  return j;
}

}  // namespace rsibr
