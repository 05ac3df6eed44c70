#include "core/albedo_normalisation.h"

#include "core/parallel.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rsibr {

void check_albedo_table(const std::vector<float>& table) {
  if (table.size() < 6 || table.size() % 3 != 0)
    throw std::invalid_argument("albedo table: expected at least 2 rows of 3 values, got " +
                                std::to_string(table.size()) + " values");
  for (float a : table)
    if (!std::isfinite(a) || a < 0) throw std::invalid_argument("albedo table: values must be finite and >= 0");
}

Vec3 albedo_at(const std::vector<float>& table, float cos_theta) {
  const int n = int(table.size() / 3);
  // Row k sits at (k + 0.5) / n: position u = cos * n - 0.5 in rows.
  const float u = std::clamp(cos_theta * float(n) - 0.5f, 0.0f, float(n - 1));
  const int k = std::min(int(u), n - 2);
  const float f = u - float(k);
  const float* a = &table[std::size_t(3 * k)];
  return Vec3(a[0] + f * (a[3] - a[0]), a[1] + f * (a[4] - a[1]), a[2] + f * (a[5] - a[2]));
}

namespace {

template <class Op>
void for_disc_texels(cv::Mat& rgb, const std::vector<float>& table, Op op) {
  check_albedo_table(table);
  if (rgb.type() != CV_32FC3) throw std::invalid_argument("albedo normalisation: expected a CV_32FC3 map");
  const int W = rgb.cols, H = rgb.rows;
  parallel_for_rows(H, [&](int r) {
    cv::Vec3f* row = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < W; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), W, H);
      const double rho2 = xy.squaredNorm();
      if (rho2 >= 1.0) continue;
      const Vec3 a = albedo_at(table, float(std::sqrt(1.0 - rho2)));
      for (int i = 0; i < 3; ++i) row[c][i] = op(row[c][i], float(a[i]));
    }
  });
}

}  // namespace

void normalise_by_albedo(cv::Mat& rgb, const std::vector<float>& table) {
  // Clamped to the float range: a radiance far above what the albedo allows must not become Inf.
  static constexpr float kMax = std::numeric_limits<float>::max();
  for_disc_texels(rgb, table,
                  [](float L, float a) { return a > kAlbedoFloor ? std::clamp(L / a, -kMax, kMax) : 0.0f; });
}

void denormalise_by_albedo(cv::Mat& rgb, const std::vector<float>& table) {
  static constexpr float kMax = std::numeric_limits<float>::max();
  for_disc_texels(rgb, table, [](float P, float a) { return std::clamp(P * a, -kMax, kMax); });
}

}  // namespace rsibr
