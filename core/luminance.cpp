#include "core/luminance.h"

#include "core/colour.h"

namespace rsibr {

const std::array<double, 3>& luma_coefficients() {
  static const std::array<double, 3> w = [] {
    double c[3] = {0, 0, 0};
    colour_config()->getDefaultLumaCoefs(c);
    const double sum = c[0] + c[1] + c[2];
    if (!(c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && sum > 0.5 && sum < 1.5))
      return std::array<double, 3>{0.2126, 0.7152, 0.0722};
    return std::array<double, 3>{c[0] / sum, c[1] / sum, c[2] / sum};
  }();
  return w;
}

}  // namespace rsibr
