#include "core/latlong_ripmap.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// One row of out_w columns from one of in_w, both "pixel is point" over the same longitudes:
// column c covers [c - 1/2, c + 1/2] (clipped to the seam at 0 and w - 1), and each output texel
// is the overlap-weighted mean of the input texels. Weights are longitude lengths: within a row
// every texel's solid angle is its longitude length times the row's sine difference.
void shrink_row(const float* in, int in_w, float* out, int out_w, int ch) {
  const double s = double(in_w - 1) / double(out_w - 1);  // input columns per output column
  int first = 0;
  for (int c = 0; c < out_w; ++c) {
    const double lo = std::max(0.0, (c - 0.5) * s), hi = std::min(double(in_w - 1), (c + 0.5) * s);
    double acc[kMaxChannels] = {};
    double wsum = 0;
    while (first < in_w - 1 && first + 0.5 <= lo) ++first;
    for (int i = first; i < in_w; ++i) {
      const double a = std::max(lo, std::max(0.0, i - 0.5)), b = std::min(hi, std::min(double(in_w - 1), i + 0.5));
      if (a >= hi) break;
      if (b <= a) continue;
      const double w = b - a;
      for (int k = 0; k < ch; ++k) acc[k] += w * in[std::size_t(i) * ch + k];
      wsum += w;
    }
    for (int k = 0; k < ch; ++k) out[std::size_t(c) * ch + k] = wsum > 0 ? float(acc[k] / wsum) : 0.f;
  }
}

}  // namespace

LatLongRipmap::LatLongRipmap(const EnvMap& src) {
  if (src.layout.kind() != LayoutKind::LatLong || src.pixels.depth() != CV_32F)
    throw std::logic_error("LatLongRipmap: a float lat-long map is required");
  levels_.push_back(src.pixels);
  inverse_scale_.push_back(1.0);
  const int W = src.layout.width(), ch = src.channels();
  for (int j = 1;; ++j) {
    const int w = int(std::ceil(double(W - 1) / double(1L << std::min(j, 40)))) + 1;
    const cv::Mat& prev = levels_.back();
    if (w >= prev.cols || prev.cols <= 3) break;
    cv::Mat next(prev.rows, w, prev.type());
    parallel_for_rows(prev.rows, [&](int r) { shrink_row(prev.ptr<float>(r), prev.cols, next.ptr<float>(r), w, ch); });
    levels_.push_back(next);
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
