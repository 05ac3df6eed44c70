#include "core/sphere_map.h"

#include <algorithm>
#include <array>

namespace rsibr::sphere_map {
namespace {

// Antiderivative of sqrt(1-x^2) on [-1,1].
double half_chord_integral(double x) {
  x = std::clamp(x, -1.0, 1.0);
  return 0.5 * (x * std::sqrt(std::max(0.0, 1.0 - x * x)) + std::asin(x));
}

}  // namespace

//   A = int_{x0}^{x1} max(0, min(y1, h(x)) - max(y0, -h(x))) dx,  h(x) = sqrt(1-x^2).
// Between consecutive break points (where h = |y0| or h = |y1|) min and max pick fixed branches,
// so each piece integrates in closed form; the sign at the piece's midpoint decides whether the
// piece lies inside the disc at all.
double disc_rect_area(double x0, double x1, double y0, double y1) {
  x0 = std::max(x0, -1.0);
  x1 = std::min(x1, 1.0);
  if (!(x1 > x0) || !(y1 > y0)) return 0.0;
  std::array<double, 6> cuts{};
  int n = 0;
  cuts[n++] = x0;
  for (double y : {y0, y1}) {
    if (std::abs(y) < 1.0) {
      const double c = std::sqrt(1.0 - y * y);
      if (c > x0 && c < x1) cuts[n++] = c;
      if (-c > x0 && -c < x1) cuts[n++] = -c;
    }
  }
  cuts[n++] = x1;
  for (int i = 1; i < n; ++i)  // insertion sort of <= 6 values (std::sort trips GCC 12's -Warray-bounds)
    for (int j = i; j > 0 && cuts[std::size_t(j)] < cuts[std::size_t(j - 1)]; --j)
      std::swap(cuts[std::size_t(j)], cuts[std::size_t(j - 1)]);
  double area = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(b > a)) continue;
    const double m = 0.5 * (a + b);
    const double hm = std::sqrt(std::max(0.0, 1.0 - m * m));
    const bool top_is_h = hm <= y1;   // min(y1, h) = h on this piece
    const bool bot_is_h = -hm >= y0;  // max(y0, -h) = -h on this piece
    const double top = top_is_h ? hm : y1;
    const double bot = bot_is_h ? -hm : y0;
    if (!(top > bot)) continue;
    const double H = half_chord_integral(b) - half_chord_integral(a);
    const double w = b - a;
    area += (top_is_h ? H : y1 * w) - (bot_is_h ? -H : y0 * w);
  }
  return area;
}

}  // namespace rsibr::sphere_map
