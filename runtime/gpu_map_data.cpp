#include "runtime/gpu_map_data.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

namespace rsibr {

GpuMapData gpu_map_data(const MapSet& maps, const ViewSet& view_set, const BlendOptions& blend) {
  check_blend_inputs(maps, view_set);
  if (blend.barycentric != Barycentric::Gnomonic)
    throw std::invalid_argument("viewer: the GPU path implements the gnomonic barycentric weights only");
  if (view_set.triangles().empty())
    throw std::invalid_argument("viewer: the map set's views have no spherical triangle (at least 3 views needed)");
  GpuMapData d;
  const int W = maps.width(), H = maps.height(), N = int(maps.views.size());
  d.width = W, d.height = H, d.views = N;

  d.maps.resize(std::size_t(W) * H * 4 * N);
  for (int i = 0; i < N; ++i) {
    check_blend_source(maps, i);
    const MapView& v = maps.views[std::size_t(i)];
    const bool conf = blend.use_confidence && !v.confidence.empty();
    for (int r = 0; r < H; ++r) {
      const float* s = v.rgb.ptr<float>(r);
      const float* c = conf ? v.confidence.ptr<float>(r) : nullptr;
      float* o = d.maps.data() + ((std::size_t(i) * H + r) * W) * 4;
      for (int x = 0; x < W; ++x) {
        o[4 * x] = s[3 * x];
        o[4 * x + 1] = s[3 * x + 1];
        o[4 * x + 2] = s[3 * x + 2];
        o[4 * x + 3] = c ? c[x] : 1.f;
      }
    }
  }

  d.view_data.assign(std::size_t(N) * 4 * 4, 0.f);
  for (int i = 0; i < N; ++i) {
    const MapView& v = maps.views[std::size_t(i)];
    for (int row = 0; row < 3; ++row)
      for (int k = 0; k < 3; ++k) d.view_data[(std::size_t(row) * N + i) * 4 + k] = float(v.world_from_view(k, row));
    d.view_data[std::size_t(i) * 4 + 3] = v.warp == CentralDirection::Mirror ? 0.f : 1.f;
    const Vec3& u = view_set.views()[std::size_t(i)];
    for (int k = 0; k < 3; ++k) d.view_data[(std::size_t(3) * N + i) * 4 + k] = float(u[k]);
  }

  const auto& tris = view_set.triangles();
  const auto& views = view_set.views();
  const int T = int(tris.size());
  d.triangle_count = T;
  d.edge_planes.assign(std::size_t(T) * 3 * 4, 0.f);
  for (int t = 0; t < T; ++t) {
    const auto& tri = tris[std::size_t(t)];
    d.triangles.insert(d.triangles.end(), {tri[0], tri[1], tri[2], 0});
    for (int e = 0; e < 3; ++e) {
      const Vec3 n =
          views[std::size_t(tri[std::size_t(e)])].cross(views[std::size_t(tri[std::size_t((e + 1) % 3)])]).normalized();
      for (int k = 0; k < 3; ++k) d.edge_planes[(std::size_t(e) * T + t) * 4 + k] = float(n[k]);
    }
  }

  if (!view_set.surrounds()) {
    std::map<std::pair<int, int>, int> edges;  // undirected edge -> triangles holding it
    for (const auto& tri : tris)
      for (int e = 0; e < 3; ++e) {
        const int a = tri[std::size_t(e)], b = tri[std::size_t((e + 1) % 3)];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    for (int t = 0; t < T; ++t)
      for (int e = 0; e < 3; ++e) {
        const int a = tris[std::size_t(t)][std::size_t(e)], b = tris[std::size_t(t)][std::size_t((e + 1) % 3)];
        if (edges[{std::min(a, b), std::max(a, b)}] == 1) d.arcs.insert(d.arcs.end(), {a, b, t, 0});
      }
  }
  d.arc_count = int(d.arcs.size() / 4);
  if (d.arcs.empty()) d.arcs.assign(4, 0);
  return d;
}

}  // namespace rsibr
