// Rendering the bunny (cache/assets/models/bunny.glb) at 1280 x 720 with a 12-view 256^2 map set
// (runtime/renderer.h), per frame, on a turntable (the camera moves every frame, so paper mode blends
// a new destination map each time). Baseline, in the same run: one rtcIntersect1 per pixel centre
// (RayScene::intersect, rows in parallel), the bare visibility cost with no shading.
#include "core/camera.h"
#include "core/mesh.h"
#include "core/parallel.h"
#include "core/patterns.h"
#include "runtime/renderer.h"

#include <benchmark/benchmark.h>

#include <atomic>
#include <filesystem>
#include <memory>

namespace rsibr {
namespace {

const std::string kBunny = std::string(RSIBR_CACHE_DIR) + "/assets/models/bunny.glb";

const Mesh* bunny() {
  static std::unique_ptr<Mesh> mesh;
  if (!mesh && std::filesystem::exists(kBunny)) mesh = std::make_unique<Mesh>(load_mesh(kBunny));
  return mesh.get();
}

// 12 views (icosahedron), 256^2, the direction-coded environment as a view-independent mirror set.
const MapSet& map_set() {
  static const MapSet set = [] {
    MapSet s;
    const auto f = patterns::direction_coded();
    const ViewSet icosa = ViewSet::icosahedron();
    for (const Vec3& v : icosa.views()) {
      MapView mv;
      mv.view = v;
      mv.world_from_view = world_from_view_for(v);
      const Mat3 T = mv.world_from_view;
      mv.rgb =
          render_pattern([&](const Vec3& d) { return f(T * d); }, Layout::with_size(LayoutKind::Sphere, 256), 1).pixels;
      s.views.push_back(std::move(mv));
    }
    return s;
  }();
  return set;
}

// The CLI's default framing (cli/camera_options.h: --from 0,0.3,1, 40 degrees), frame k of 36.
Camera camera(const Mesh& mesh, int k) {
  const Camera c = frame_bounds(mesh.bounds(), -Vec3(0, 0.3, 1), Vec3(0, 1, 0), 40, 1280, 720);
  return orbit(c, mesh.bounds().center().cast<double>(), Vec3(0, 1, 0), k % 36, 36);
}

void BM_RenderBaseline(benchmark::State& state) {
  const Mesh* mesh = bunny();
  if (!mesh) return state.SkipWithError(("absent: " + kBunny).c_str());
  const RayScene scene(*mesh);
  int k = 0;
  for (auto _ : state) {
    const Camera cam = camera(*mesh, k++);
    std::atomic<long> hits{0};
    parallel_for_rows(cam.height, [&](int r) {
      long h = 0;
      for (int c = 0; c < cam.width; ++c) h += scene.intersect(cam.eye, cam.ray_direction(c, r)).hit;
      hits += h;
    });
    benchmark::DoNotOptimize(hits.load());
  }
  state.SetLabel("rtcIntersect1 per pixel, 1280x720");
}

void BM_Render(benchmark::State& state) {
  const Mesh* mesh = bunny();
  if (!mesh) return state.SkipWithError(("absent: " + kBunny).c_str());
  const int kind = int(state.range(0));  // 0 packets only, 1 paper precomputed, 2 paper tessellated, 3 per-pixel
  RenderOptions o;
  o.mode = kind == 3 ? RenderMode::PerPixel : RenderMode::Paper;
  o.warp = kind == 2 ? "tessellated" : "precomputed";
  o.map_size = 256;
  const MapSet& set = map_set();
  const Renderer renderer(*mesh, {&set}, o);
  int k = 0;
  long long hits = 0;
  for (auto _ : state) {
    const Camera cam = camera(*mesh, k++);
    if (kind == 0) {
      hits += renderer.trace_only(cam);
    } else {
      RenderStats stats;
      cv::Mat img = renderer.render(cam, &stats);
      benchmark::DoNotOptimize(img.data);
      hits += stats.hits;
    }
  }
  const char* names[] = {"primary rays only (packets of 16)", "paper mode, precomputed warp, 256^2",
                         "paper mode, tessellated warp, 256^2", "per-pixel mode"};
  state.SetLabel(std::string(names[kind]) + ", 1280x720, " +
                 std::to_string(hits / std::max<long long>(1, state.iterations())) + " hits/frame");
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// 36 iterations: every case renders the same 36 turntable frames.
BENCHMARK(BM_RenderBaseline)->Iterations(36)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Render)->DenseRange(0, 3)->Iterations(36)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace rsibr
