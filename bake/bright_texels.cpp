#include "bake/bright_texels.h"

#include "core/parallel.h"
#include "core/luminance.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace rsibr {

namespace {
double texel_luminance(const float* p) { return positive_luminance(p); }
}  // namespace

EnvironmentSplit split_bright_texels(const EnvMap& env, const BrightTexelOptions& options) {
  if (env.layout.kind() != LayoutKind::LatLong)
    throw std::invalid_argument("bright texels: the environment must be lat-long");
  if (env.pixels.depth() != CV_32F || env.channels() < 3)
    throw std::invalid_argument("bright texels: the environment must be CV_32F with >= 3 channels");
  EnvironmentSplit out;
  out.remainder = env;
  out.remainder.pixels = env.pixels.clone();
  if (!(options.ratio > 0) || options.max_count <= 0) return out;
  const int w = env.layout.width(), h = env.layout.height(), ch = env.channels();
  struct Candidate {
    long texel;
    double lum, omega;
  };
  // Power and area per row (rows in parallel, summed in row order: the same bits on any threads).
  std::vector<double> row_power(std::size_t(h), 0.0), row_area(std::size_t(h), 0.0);
  parallel_for_rows(h, [&](int r) {
    const float* row = env.pixels.ptr<float>(r);
    const double seam = env.layout.texel_solid_angle(0, r), inner = env.layout.texel_solid_angle(w > 2 ? 1 : 0, r);
    double p = 0, a = 0;
    for (int c = 0; c < w; ++c) {
      const double omega = c == 0 || c == w - 1 ? seam : inner;  // a lat-long row: equal but the seams
      p += texel_luminance(row + c * ch) * omega;
      a += omega;
    }
    row_power[std::size_t(r)] = p, row_area[std::size_t(r)] = a;
  });
  double power = 0, area = 0;
  for (int r = 0; r < h; ++r) power += row_power[std::size_t(r)], area += row_area[std::size_t(r)];
  if (!(power > 0) || !std::isfinite(power)) return out;
  const double threshold = options.ratio * power / area;
  std::vector<std::vector<Candidate>> row_bright(static_cast<std::size_t>(h));
  parallel_for_rows(h, [&](int r) {
    const float* row = env.pixels.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      const double lum = texel_luminance(row + c * ch);
      if (!(lum >= threshold)) continue;
      const double omega = env.layout.texel_solid_angle(c, r);
      if (omega > 0) row_bright[std::size_t(r)].push_back({long(r) * w + c, lum, omega});
    }
  });
  std::vector<Candidate> bright;
  for (const auto& row : row_bright) bright.insert(bright.end(), row.begin(), row.end());
  // Brightest power first; ties by texel index (deterministic).
  std::sort(bright.begin(), bright.end(), [](const Candidate& a, const Candidate& b) {
    const double pa = a.lum * a.omega, pb = b.lum * b.omega;
    return pa != pb ? pa > pb : a.texel < b.texel;
  });
  if (int(bright.size()) > options.max_count) bright.resize(std::size_t(options.max_count));
  double share = 0;
  for (const Candidate& q : bright) {
    const int r = int(q.texel / w), c = int(q.texel % w);
    float* p = out.remainder.pixels.ptr<float>(r) + c * ch;
    BrightTexel b;
    b.texel = q.texel;
    b.radiance = Vec3(p[0], p[1], p[2]);
    b.solid_angle = q.omega;
    b.angular_size = std::sqrt(q.omega);
    // Half the diagonal of the cell's latitude x longitude extent (an upper bound in angle).
    b.radius = 0.5 * std::hypot(kPi / (h - 1), 2 * kPi / (w - 1));
    out.bright.push_back(b);
    for (int k = 0; k < ch; ++k) p[k] = 0.f;
    share += q.lum * q.omega;
  }
  out.bright_share = share / power;

  // Cluster levels (see the header).
  std::vector<Vec3> centres;
  // Texel directions as the reference quadrature uses them (Layout::texel_direction).
  for (const BrightTexel& b : out.bright)
    centres.push_back(env.layout.texel_direction(int(b.texel % w), int(b.texel / w))->normalized());
  for (double degrees : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {
    BrightClusterLevel level;
    level.max_radius = degrees * kPi / 180.0;
    const double cos_r = std::cos(level.max_radius);
    std::vector<Vec3> seeds, sums;
    std::vector<std::vector<std::size_t>> members;
    for (std::size_t i = 0; i < out.bright.size(); ++i) {  // brightest first
      std::size_t j = 0;
      while (j < seeds.size() && !(seeds[j].dot(centres[i]) >= cos_r)) ++j;
      if (j == seeds.size()) {
        seeds.push_back(centres[i]);
        members.emplace_back();
      }
      members[j].push_back(i);
    }
    for (const auto& group : members) {
      BrightCluster cl;
      Vec3 weighted = Vec3::Zero();
      for (std::size_t i : group) {
        const BrightTexel& b = out.bright[i];
        cl.power += b.radiance * b.solid_angle;
        const double lum = luminance(b.radiance);
        weighted += std::max(lum, 1e-30) * b.solid_angle * centres[i];
      }
      cl.dir = weighted.normalized();
      for (std::size_t i : group) cl.radius = std::max(cl.radius, angle_between(cl.dir, centres[i]));
      level.clusters.push_back(cl);
    }
    out.levels.push_back(std::move(level));
  }
  return out;
}

const BrightClusterLevel* cluster_level_for(const EnvironmentSplit& split, double lobe_width) {
  const BrightClusterLevel* level = nullptr;
  for (const BrightClusterLevel& l : split.levels)
    if (l.max_radius <= kClusterFraction * lobe_width) level = &l;
  return level;
}

Vec3 bright_texel_radiance(const Brdf& brdf, const shading::Frame& frame, const Vec3& wo, const EnvironmentSplit& split,
                           const Layout& cells) {
  const std::vector<BrightTexel>& bright = split.bright;
  if (bright.empty()) return Vec3::Zero();
  const Vec3 n = frame.normal();
  const double lobe = std::max(brdf.lobe_width(wo), 1e-6);
  Vec3 sum = Vec3::Zero();
  if (const BrightClusterLevel* level = cluster_level_for(split, lobe)) {
    for (const BrightCluster& cl : level->clusters) {
      const Vec3 wi = frame.to_local(cl.dir);
      if (wi.z() > 0) sum += brdf.eval(wo, wi).cwiseProduct(cl.power);
    }
    return sum;
  }
  for (const BrightTexel& b : bright) {
    // Skip cells wholly below the horizon: the centre more than the cell's radius below it.
    const Vec3 centre = cells.texel_direction(int(b.texel % cells.width()), int(b.texel / cells.width()))->normalized();
    if (n.dot(centre) < -std::sin(std::min(b.radius, 0.5 * kPi))) continue;
    const int k = std::clamp(int(std::ceil(4.0 * b.angular_size / lobe)), 1, 8);
    Vec3 cell = Vec3::Zero();
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const Vec3 w = k == 1 ? centre : latlong_cell_direction(cells, b.texel, Vec2((i + 0.5) / k, (j + 0.5) / k));
        const Vec3 wi = frame.to_local(w);
        if (wi.z() > 0) cell += brdf.eval(wo, wi);
      }
    sum += b.radiance.cwiseProduct(cell) * (b.solid_angle / (k * k));
  }
  return sum;
}

}  // namespace rsibr
