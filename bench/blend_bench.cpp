// Reflection-space blend of a destination map (runtime/blend.h), per frame, against two OpenCV
// baselines measured in the same run:
//   BM_OpenCvBlend (the OpenCV blend baseline): per frame, compute the three coordinate maps (map_x, map_y,
//     CV_32FC1) with the exact warp (runtime/warp.h, every destination texel inside the disc, rows in
//     parallel), cv::remap (INTER_LINEAR) each source, and sum with per-texel weights (barycentric
//     weight x rim fade), normalised per texel. No tap dropping at the source rim, no fallback.
//   BM_RemapThreeMaps: only three bare cv::remap calls with precomputed maps (no warp maths, no fades,
//     no sum): a floor, not a blend.
#include "core/patterns.h"
#include "previous_blend.h"
#include "runtime/blend.h"
#include "runtime/blend_engine.h"
#include "runtime/tessellated_warp.h"

#include "core/sphere_map.h"

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <map>

namespace rsibr {
namespace {

// A view-independent mirror map set of the direction-coded environment over the icosahedron. With
// `confidence`, each map carries a confidence channel as captured maps do (1 at the centre falling
// to 0.2 at the rim).
const MapSet& mirror_set(int size, bool confidence = false) {
  static std::map<std::pair<int, bool>, MapSet> cache;
  auto it = cache.find({size, confidence});
  if (it != cache.end()) return it->second;
  MapSet set;
  const auto f = patterns::direction_coded();
  const ViewSet icosa = ViewSet::icosahedron();  // named: views() refers into it
  for (const Vec3& v : icosa.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v);
    const Mat3 T = mv.world_from_view;
    mv.rgb =
        render_pattern([&](const Vec3& d) { return f(T * d); }, Layout::with_size(LayoutKind::Sphere, size), 1).pixels;
    if (confidence) {
      mv.confidence.create(size, size, CV_32FC1);
      for (int r = 0; r < size; ++r)
        for (int c = 0; c < size; ++c)
          mv.confidence.at<float>(r, c) =
              float(1.0 - 0.8 * sphere_map::disc_from_pixel(Vec2(c, r), size, size).squaredNorm());
    }
    set.views.push_back(std::move(mv));
  }
  return cache.emplace(std::make_pair(size, confidence), std::move(set)).first->second;
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
  state.SetLabel(std::to_string(n) + "^2, three bare remaps");
}

// Issue 4's baseline: the whole blend from OpenCV building blocks, per frame.
void BM_OpenCvBlend(benchmark::State& state) {
  const int n = int(state.range(0));
  const MapSet& set = mirror_set(n);
  const ViewSet views = set.view_set();
  const double rim_fade = BlendOptions{}.rim_fade;
  cv::Mat map_x[3], map_y[3], weight[3], warped[3], weight3, acc, total, total3, out;
  for (auto _ : state) {
    const Mat3 T_d = world_from_view_for(kView, Vec3(0, 1, 0));
    const ViewWeights located = views.locate(kView, Barycentric::Gnomonic);
    acc = cv::Mat::zeros(n, n, CV_32FC3);
    total = cv::Mat::zeros(n, n, CV_32FC1);
    for (int k = 0; k < located.count; ++k) {
      const MapView& v = set.views[std::size_t(located.views[std::size_t(k)])];
      const Mat3 M = v.world_from_view.transpose() * T_d;
      const CentralDirection kind = v.warp;
      const double w = located.weights[std::size_t(k)];
      map_x[k].create(n, n, CV_32FC1);
      map_y[k].create(n, n, CV_32FC1);
      weight[k].create(n, n, CV_32FC1);
      // 1. The coordinate maps and weights (exact warp; texels outside the disc read nothing).
      cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
          float* mx = map_x[k].ptr<float>(r);
          float* my = map_y[k].ptr<float>(r);
          float* wt = weight[k].ptr<float>(r);
          const auto [c0, c1] = disc_span(r, n, n);
          for (int c = 0; c < n; ++c) {
            if (c < c0 || c >= c1) {
              mx[c] = my[c] = -2.f;
              wt[c] = 0.f;
              continue;
            }
            const WarpSample s =
                warp_direction(kind, M * central_direction(kind, sphere_map::disc_from_pixel(Vec2(c, r), n, n)));
            const Vec2 p = sphere_map::pixel_from_disc(s.disc, n, n);
            mx[c] = float(p.x());
            my[c] = float(p.y());
            wt[c] = float(w * rim_fade_weight(s.rim, rim_fade));
          }
        }
      });
      // 2. Remap the source; 3. accumulate weight x sample.
      cv::remap(v.rgb, warped[k], map_x[k], map_y[k], cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      cv::merge(std::vector<cv::Mat>{weight[k], weight[k], weight[k]}, weight3);
      cv::multiply(warped[k], weight3, warped[k]);
      acc += warped[k];
      total += weight[k];
    }
    // 4. Normalise per texel (0 where the total weight is 0).
    cv::merge(std::vector<cv::Mat>{total, total, total}, total3);
    cv::divide(acc, total3, out);
    out.setTo(0.f, total3 == 0.f);
    benchmark::DoNotOptimize(out.data);
  }
  state.SetLabel(std::to_string(n) + "^2, 3 sources: warp maps + remap + weighted sum");
}

// One frame's blend of size^2 for warp kind 0 exact, 1 precomputed, 2 tessellated (16 x 64), 3 exact
// with a confidence channel in every source (as captured maps carry). Paths:
// 0 the blend engine, built once (sources laid out once, as the renderer and the viewer hold it), one
// map() per frame; 1 blend(), one call per frame (an engine per call: the located sources laid out
// each time); 2 the tile path before the engine (bench/previous_blend.h).
void blend_frames(benchmark::State& state, int n, int kind, int path) {
  const MapSet& set = mirror_set(n, kind == 3);
  const ViewSet views = set.view_set();
  const PrecomputedWarp table(n, n);
  const TessellatedWarp mesh(n, n);
  BlendOptions options;
  if (kind == 1) options.warp = &table;
  if (kind == 2) options.warp = &mesh;
  const BlendEngine engine(set, views, options);
  engine.prepare_all();
  BlendResult kept;  // the engine's frames: one result reused, as the renderer and the viewer keep it
  for (auto _ : state) {
    if (path == 0) {
      engine.map(kView, Vec3(0, 1, 0), options, kept);
      benchmark::DoNotOptimize(kept.rgb.data);
      continue;
    }
    BlendResult r = path == 1 ? blend(set, views, kView, Vec3(0, 1, 0), options)
                              : previous::blend(set, views, kView, Vec3(0, 1, 0), options);
    benchmark::DoNotOptimize(r.rgb.data);
  }
  const char* names[] = {"exact warp", "precomputed directions", "tessellated disk 16x64",
                         "exact warp, confidence channel"};
  const char* paths[] = {"engine", "blend(), one call", "previous tile path"};
  state.SetLabel(std::to_string(n) + "^2, " + names[kind] + ", " + paths[path]);
}

// Against the OpenCV baseline: the engine and the one-call form.
void BM_Blend(benchmark::State& state) {
  blend_frames(state, int(state.range(0)), int(state.range(1)), int(state.range(2)));
}
// Against the tile path before the engine, same size and warp.
void BM_BlendEngine(benchmark::State& state) { blend_frames(state, int(state.range(0)), int(state.range(1)), 0); }
void BM_PreviousTilePath(benchmark::State& state) { blend_frames(state, int(state.range(0)), int(state.range(1)), 2); }

BENCHMARK(BM_RemapThreeMaps)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OpenCvBlend)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Blend)->ArgsProduct({{256, 512}, {0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PreviousTilePath)->ArgsProduct({{256, 512}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BlendEngine)->ArgsProduct({{256, 512}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace rsibr
