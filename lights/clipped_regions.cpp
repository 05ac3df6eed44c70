#include "lights/clipped_regions.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace rsibr {

namespace {

struct UnionFind {
  std::vector<long> parent;
  explicit UnionFind(long n) : parent(std::size_t(n)) { std::iota(parent.begin(), parent.end(), 0L); }
  long find(long x) {
    while (parent[std::size_t(x)] != x) x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  }
  void join(long a, long b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::size_t(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

std::vector<ClippedRegion> find_clipped_regions(const Probe& probe, double merge_deg) {
  const Layout& layout = probe.env.layout;
  const int W = layout.width(), H = layout.height();
  if (probe.clipped.empty() || probe.clipped.rows != H || probe.clipped.cols != W) return {};
  auto clipped = [&](int r, int c) { return probe.clipped.at<float>(r, c) > 0; };
  // Canonical texel of each direction: the seam column W-1 is column 0; a pole row is one texel.
  auto canonical = [&](int r, int c) -> long {
    if (r == 0 || r == H - 1) c = 0;
    if (c == W - 1) c = 0;
    return long(r) * W + c;
  };
  UnionFind uf(long(W) * H);
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      if (!clipped(r, c)) continue;
      uf.join(long(r) * W + c, canonical(r, c));
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int r2 = r + dr;
          if (r2 < 0 || r2 >= H || (dr == 0 && dc == 0)) continue;
          const int c2 = (c + dc + (W - 1)) % (W - 1);  // columns 0..W-2 are distinct, W-1 repeats 0
          if (clipped(r2, c2)) uf.join(long(r) * W + c, long(r2) * W + c2);
        }
    }
  std::vector<long> root_index(std::size_t(W) * H, -1);
  std::vector<ClippedRegion> regions;
  std::vector<Vec3> sums;
  const double half_diagonal = 0.5 * std::hypot(kPi / (H - 1), 2 * kPi / (W - 1));
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      if (!clipped(r, c)) continue;
      const long root = uf.find(long(r) * W + c);
      long& idx = root_index[std::size_t(root)];
      if (idx < 0) {
        idx = long(regions.size());
        regions.emplace_back();
        sums.push_back(Vec3::Zero());
      }
      ClippedRegion& g = regions[std::size_t(idx)];
      const double omega = layout.texel_solid_angle(c, r);
      const Vec3 w = layout.texel_direction(c, r)->normalized();
      const cv::Vec3f lb = probe.lower_bound.at<cv::Vec3f>(r, c);
      g.texels.push_back(long(r) * W + c);
      g.solid_angle += omega;
      g.lower_bound += omega * Vec3(lb[0], lb[1], lb[2]);
      g.weight += probe.clipped.at<float>(r, c);
      sums[std::size_t(idx)] += omega * w;
    }
  auto finish = [&](ClippedRegion& g, const Vec3& sum) {
    g.direction = sum.norm() > 0 ? sum.normalized()
                                 : layout.texel_direction(int(g.texels[0] % W), int(g.texels[0] / W))->normalized();
    double rad = 0;
    for (long t : g.texels)
      rad = std::max(rad, angle_between(g.direction, *layout.texel_direction(int(t % W), int(t / W))));
    g.radius = rad + half_diagonal;
  };
  for (std::size_t i = 0; i < regions.size(); ++i) finish(regions[i], sums[i]);
  auto by_bound = [](const ClippedRegion& a, const ClippedRegion& b) {
    const double la = a.lower_bound.sum(), lb = b.lower_bound.sum();
    return la != lb ? la > lb : a.texels.front() < b.texels.front();
  };
  // Merge: each component, largest lower bound first, joins the first merged region whose
  // centroid (as merged so far) is within merge_deg of its own.
  std::vector<std::size_t> order(regions.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return by_bound(regions[a], regions[b]); });
  std::vector<ClippedRegion> merged;
  std::vector<Vec3> merged_sums;
  const double cos_merge = std::cos(merge_deg * kPi / 180);
  for (std::size_t i : order) {
    std::size_t j = 0;
    while (j < merged.size() && !(merged[j].direction.dot(regions[i].direction) >= cos_merge)) ++j;
    if (j == merged.size()) {
      merged.push_back(regions[i]);
      merged_sums.push_back(sums[i]);
      continue;
    }
    ClippedRegion& m = merged[j];
    m.texels.insert(m.texels.end(), regions[i].texels.begin(), regions[i].texels.end());
    std::sort(m.texels.begin(), m.texels.end());
    m.solid_angle += regions[i].solid_angle;
    m.lower_bound += regions[i].lower_bound;
    m.weight += regions[i].weight;
    merged_sums[j] += sums[i];
    finish(m, merged_sums[j]);
  }
  std::stable_sort(merged.begin(), merged.end(), by_bound);
  return merged;
}

}  // namespace rsibr
