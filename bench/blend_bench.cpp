// Reflection-space blend of a destination map (runtime/blend.h), per frame. Baseline: OpenCV's
// remap of the three located source maps with precomputed maps (the bare cost of three bilinear
// lookups per texel, no warp maths, no fades), in the same run.
#include "core/patterns.h"
#include "runtime/blend.h"
#include "runtime/tessellated_warp.h"

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

namespace rsibr {
namespace {

// A view-independent mirror map set of the direction-coded environment over the icosahedron.
const MapSet& mirror_set(int size) {
  static std::map<int, MapSet> cache;
  auto it = cache.find(size);
  if (it != cache.end()) return it->second;
  MapSet set;
  const auto f = patterns::direction_coded();
  const ViewSet icosa = ViewSet::icosahedron();  // named: views() refers into it
  for (const Vec3& v : icosa.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v);
    const Mat3 T = mv.world_from_view;
    mv.rgb = render_pattern([&](const Vec3& d) { return f(T * d); }, Layout::with_size(LayoutKind::Sphere, size), 1)
                 .pixels;
    set.views.push_back(std::move(mv));
  }
  return cache.emplace(size, std::move(set)).first->second;
}

const Vec3 kView = Vec3(0.3, 0.5, 0.8).normalized();

void BM_RemapThreeMaps(benchmark::State& state) {
  const int n = int(state.range(0));
  const MapSet& set = mirror_set(n);
  cv::Mat mx(n, n, CV_32FC1), my(n, n, CV_32FC1);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      mx.at<float>(r, c) = float(n - 1 - c);  // any non-trivial map: a mirrored lookup
      my.at<float>(r, c) = float(r);
    }
  cv::Mat out[3];
  for (auto _ : state) {
    for (int i = 0; i < 3; ++i) cv::remap(set.views[std::size_t(i)].rgb, out[i], mx, my, cv::INTER_LINEAR);
    benchmark::DoNotOptimize(out[2].data);
  }
  state.SetLabel(std::to_string(n) + "^2");
}

void BM_Blend(benchmark::State& state) {
  const int n = int(state.range(0));
  const int kind = int(state.range(1));  // 0 exact, 1 precomputed, 2 tessellated (16 x 64)
  const MapSet& set = mirror_set(n);
  const ViewSet views = set.view_set();
  const PrecomputedWarp table(n, n);
  const TessellatedWarp mesh(n, n);
  BlendOptions options;
  if (kind == 1) options.warp = &table;
  if (kind == 2) options.warp = &mesh;
  for (auto _ : state) {
    BlendResult r = blend(set, views, kView, Vec3(0, 1, 0), options);
    benchmark::DoNotOptimize(r.rgb.data);
  }
  const char* names[] = {"exact warp", "precomputed directions", "tessellated disk 16x64"};
  state.SetLabel(std::to_string(n) + "^2, " + names[kind]);
}

BENCHMARK(BM_RemapThreeMaps)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Blend)->ArgsProduct({{256, 512}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rsibr
