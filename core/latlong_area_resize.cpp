#include "core/latlong_area_resize.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

// Overlap weights between the cells of n_in and n_out "pixel is point" samples of one interval:
// cell i of n covers [i - 1/2, i + 1/2] in units of the interval / (n - 1), clipped to the ends.
// measure(a, b) is the weight of [a, b] given as fractions of the interval (0..1).
struct Overlap {
  int in;
  double weight;
};
template <class Measure>
std::vector<std::vector<Overlap>> overlaps(int n_in, int n_out, const Measure& measure) {
  std::vector<std::vector<Overlap>> out(static_cast<std::size_t>(n_out));
  const double in_step = 1.0 / (n_in - 1), out_step = 1.0 / (n_out - 1);
  int first = 0;
  for (int o = 0; o < n_out; ++o) {
    const double lo = std::max(0.0, (o - 0.5) * out_step), hi = std::min(1.0, (o + 0.5) * out_step);
    while (first < n_in - 1 && (first + 0.5) * in_step <= lo) ++first;
    for (int i = first; i < n_in; ++i) {
      const double a = std::max(lo, (i - 0.5) * in_step), b = std::min(hi, (i + 0.5) * in_step);
      if (a >= hi) break;
      if (b > a) out[std::size_t(o)].push_back({i, measure(a, b)});
    }
  }
  return out;
}

void weighted_row(const std::vector<Overlap>& weights, const float* in, float* out, int channels) {
  double acc[kMaxChannels] = {};
  double total = 0;
  for (const Overlap& o : weights) {
    for (int k = 0; k < channels; ++k) acc[k] += o.weight * in[std::size_t(o.in) * channels + k];
    total += o.weight;
  }
  for (int k = 0; k < channels; ++k) out[k] = total > 0 ? float(acc[k] / total) : 0.f;
}

}  // namespace

EnvMap latlong_area_resize(const EnvMap& src, int width, int height) {
  if (src.layout.kind() != LayoutKind::LatLong || src.pixels.depth() != CV_32F)
    throw std::logic_error("latlong_area_resize: a float lat-long map is required");
  const int ch = src.channels(), in_w = src.layout.width(), in_h = src.layout.height();
  EnvMap out = EnvMap::zeros(Layout(LayoutKind::LatLong, width, height), ch);
  out.attributes = src.attributes;
  // Longitude first, row by row: weights are overlap lengths.
  cv::Mat rows(in_h, width, src.pixels.type());
  const auto lon = overlaps(in_w, width, [](double a, double b) { return b - a; });
  parallel_for_rows(in_h, [&](int r) {
    const float* in = src.pixels.ptr<float>(r);
    float* o = rows.ptr<float>(r);
    for (int c = 0; c < width; ++c) weighted_row(lon[std::size_t(c)], in, o + std::size_t(c) * ch, ch);
  });
  if (height == in_h) {  // the rows are the output's
    out.pixels = rows;
    return out;
  }
  // Then latitude: a fraction f of the interval from the north pole is latitude pi/2 - pi f, and
  // the solid angle of [f_a, f_b] is proportional to sin(lat_a) - sin(lat_b).
  const auto lat = overlaps(
      in_h, height, [](double a, double b) { return std::sin(0.5 * kPi - kPi * a) - std::sin(0.5 * kPi - kPi * b); });
  parallel_for_rows(height, [&](int r) {
    float* o = out.pixels.ptr<float>(r);
    std::vector<double> acc(std::size_t(width) * std::size_t(ch), 0.0);
    double total = 0;
    for (const Overlap& w : lat[std::size_t(r)]) {
      const float* in = rows.ptr<float>(w.in);
      for (std::size_t i = 0; i < acc.size(); ++i) acc[i] += w.weight * in[i];
      total += w.weight;
    }
    for (std::size_t i = 0; i < acc.size(); ++i) o[i] = total > 0 ? float(acc[i] / total) : 0.f;
  });
  return out;
}

}  // namespace rsibr
