#include "bake/environment_distribution.h"
#include "core/luminance.h"
#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// Index i with cdf[i] <= u < cdf[i+1], skipping zero-probability bins; cdf has n+1 entries,
// cdf[0] = 0, cdf[n] = 1.
int find_bin(const double* cdf, int n, double u) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, u);
  int i = int(it - cdf) - 1;
  i = std::clamp(i, 0, n - 1);
  while (i > 0 && !(cdf[i + 1] > cdf[i])) --i;  // u == 1 rounding: last non-empty bin
  while (i < n - 1 && !(cdf[i + 1] > cdf[i])) ++i;
  return i;
}

// Normalises a CDF in place from the weights; returns the total. All-zero: uniform. weight may
// be cdf + 1 (the weights are read before they are overwritten).
double build_cdf(const double* weight, int n, double* cdf) {
  cdf[0] = 0;
  for (int i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + weight[i];
  const double total = cdf[n];
  if (total > 0) {
    for (int i = 1; i <= n; ++i) cdf[i] /= total;
  } else {
    for (int i = 1; i <= n; ++i) cdf[i] = double(i) / n;
  }
  cdf[n] = 1.0;
  return total;
}

}  // namespace

EnvironmentDistribution::EnvironmentDistribution(const EnvMap& env) : layout_(env.layout) {
  if (layout_.kind() != LayoutKind::LatLong)
    throw std::invalid_argument("EnvironmentDistribution: the environment must be lat-long (got " +
                                to_string(layout_.kind()) + ")");
  if (env.pixels.depth() != CV_32F || env.channels() < 3)
    throw std::invalid_argument("EnvironmentDistribution: the environment must be CV_32F with >= 3 channels");
  w_ = layout_.width();
  h_ = layout_.height();
  const std::size_t n = std::size_t(w_) * std::size_t(h_);
  // A lat-long texel's solid angle is its row's times its column's share (half at the seams).
  row_omega_.resize(std::size_t(h_));
  for (int r = 0; r < h_; ++r)
    row_omega_[std::size_t(r)] = w_ > 2 ? layout_.texel_solid_angle(1, r) : 2 * layout_.texel_solid_angle(0, r);
  // Per row: the weights L_lum * Omega as the row's CDF (unnormalised first), then the totals in
  // row order (the same sum whatever the threads).
  density_.resize(n);
  conditional_.resize(std::size_t(h_) * (w_ + 1));
  std::vector<double> row_weight(std::size_t(h_), 0.0);
  const int ch = env.channels();
  const auto weigh_rows = [&](bool uniform) {
    parallel_for_rows(h_, [&](int r) {
      const float* row = env.pixels.ptr<float>(r);
      double* cdf = &conditional_[std::size_t(r) * (w_ + 1)];
      double* density = &density_[std::size_t(r) * w_];
      for (int c = 0; c < w_; ++c) {
        density[c] = uniform ? 1.0 : positive_luminance(row + c * ch);  // density, before the total
        cdf[c + 1] = density[c] * solid_angle(long(r) * w_ + c);
      }
      row_weight[std::size_t(r)] = build_cdf(cdf + 1, w_, cdf);
    });
    double total = 0;
    for (double x : row_weight) total += x;
    return total;
  };
  double total = weigh_rows(false);
  // Nothing to follow (or an Inf): uniform on the sphere.
  if (!(total > 0) || !std::isfinite(total)) total = weigh_rows(true);
  // density = prob / Omega = L_lum * Omega / total / Omega.
  parallel_for_rows(h_, [&](int r) {
    double* density = &density_[std::size_t(r) * w_];
    for (int c = 0; c < w_; ++c) density[c] /= total;
  });
  marginal_.resize(std::size_t(h_) + 1);
  build_cdf(row_weight.data(), h_, marginal_.data());
}

EnvironmentDistribution::Sample EnvironmentDistribution::sample(const Vec2& u) const {
  const int r = find_bin(marginal_.data(), h_, u.x());
  const double* cdf = &conditional_[std::size_t(r) * (w_ + 1)];
  const int c = find_bin(cdf, w_, u.y());
  // Reuse the position of u within its CDF bin as the position within the cell.
  auto frac = [](double u, double lo, double hi) { return hi > lo ? std::clamp((u - lo) / (hi - lo), 0.0, 1.0) : 0.5; };
  const double fr = frac(u.x(), marginal_[std::size_t(r)], marginal_[std::size_t(r) + 1]);
  const double fc = frac(u.y(), cdf[c], cdf[c + 1]);

  Sample out;
  out.texel = long(r) * w_ + c;
  out.dir = cell_direction(out.texel, Vec2(fr, fc));
  out.pdf = density_[std::size_t(out.texel)];
  return out;
}

Vec3 EnvironmentDistribution::cell_direction(long texel, const Vec2& f) const {
  return latlong_cell_direction(layout_, texel, f);
}

Vec3 latlong_cell_direction(const Layout& layout, long texel, const Vec2& f) {
  const int w_ = layout.width(), h_ = layout.height();
  const int r = int(texel / w_), c = int(texel % w_);
  // Cell of texel (c, r), as in Layout::texel_solid_angle (lat-long, "pixel is point").
  const double dlat = kPi / (h_ - 1), dlon = 2 * kPi / (w_ - 1);
  const double lat = 0.5 * kPi - dlat * r;
  const double top = std::min(0.5 * kPi, lat + 0.5 * dlat);
  const double bot = std::max(-0.5 * kPi, lat - 0.5 * dlat);
  const double x0 = std::max(0.0, c - 0.5), x1 = std::min(double(w_ - 1), c + 0.5);
  // Uniform in solid angle: sin(latitude) and longitude uniform.
  const double s = std::sin(bot) + f.x() * (std::sin(top) - std::sin(bot));
  const double lon = kPi - dlon * (x0 + f.y() * (x1 - x0));
  const double cl = std::sqrt(std::max(0.0, 1.0 - s * s));
  return Vec3(std::sin(lon) * cl, std::clamp(s, -1.0, 1.0), std::cos(lon) * cl);
}

long EnvironmentDistribution::texel_of(const Vec3& d_in) const {
  const Vec3 d = d_in.normalized();
  const double dlat = kPi / (h_ - 1), dlon = 2 * kPi / (w_ - 1);
  const double lat = std::asin(std::clamp(d.y(), -1.0, 1.0));
  const double lon = std::atan2(d.x(), d.z());
  const int r = std::clamp(int(std::lround((0.5 * kPi - lat) / dlat)), 0, h_ - 1);
  const int c = std::clamp(int(std::lround((kPi - lon) / dlon)), 0, w_ - 1);
  return long(r) * w_ + c;
}

double EnvironmentDistribution::pdf(const Vec3& dir) const { return density_[std::size_t(texel_of(dir))]; }

}  // namespace rsibr
