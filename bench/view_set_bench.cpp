// Point location and weights in a view set. Baseline: a brute-force nearest-view search (what
// the runtime would do without a triangulation), in the same run.
#include "core/view_set.h"

#include <benchmark/benchmark.h>

#include <random>

namespace rsibr {
namespace {

std::vector<Vec3> queries() {
  std::mt19937 rng(1);
  std::normal_distribution<double> n;
  std::vector<Vec3> q(4096);
  for (Vec3& v : q) v = Vec3(n(rng), n(rng), n(rng)).normalized();
  return q;
}

void BM_NearestView(benchmark::State& state) {
  const ViewSet set = ViewSet::geodesic(int(state.range(0)));
  const auto q = queries();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(set.nearest_view(q[i++ % q.size()]));
  state.SetLabel(std::to_string(set.views().size()) + " views");
}

void BM_Locate(benchmark::State& state) {
  const ViewSet set = ViewSet::geodesic(int(state.range(0)));
  const auto q = queries();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(set.locate(q[i++ % q.size()]));
  state.SetLabel(std::to_string(set.views().size()) + " views");
}

BENCHMARK(BM_NearestView)->DenseRange(0, 3);
BENCHMARK(BM_Locate)->DenseRange(0, 3);

}  // namespace
}  // namespace rsibr
