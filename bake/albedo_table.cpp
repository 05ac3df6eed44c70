#include "bake/albedo_table.h"

#include "core/parallel.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

std::vector<float> albedo_table(const Brdf& brdf, int samples) {
  if (samples < 2) throw std::invalid_argument("albedo table: need at least 2 samples");
  std::vector<float> table(std::size_t(samples) * 3);
  parallel_for_rows(samples, [&](int k) {
    const double c = (k + 0.5) / samples;
    const Vec3 a = brdf.albedo(Vec3(std::sqrt(std::max(0.0, 1.0 - c * c)), 0.0, c));
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(a[i]) || a[i] < 0) throw std::invalid_argument("albedo table: albedo not finite and >= 0");
      table[std::size_t(3 * k + i)] = float(a[i]);
    }
  });
  return table;
}

}  // namespace rsibr
