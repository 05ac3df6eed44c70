// Layout conversion speed. Baseline: OpenCV's remap (one bilinear tap per output texel, maps
// precomputed outside the timed loop, no area weighting: aliases when shrinking and drops energy
// of a sun). Ours: rsibr::resample (area-weighted, energy-driven taps), whole call timed.
#include "core/patterns.h"
#include "core/resample.h"

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

namespace rsibr {
namespace {

const EnvMap& source() {
  // A 1024x512 lat-long sky with a 0.5-degree sun 1e5 times brighter than the sky.
  static const EnvMap env =
      render_pattern(patterns::sun_and_sky(Vec3(0.3, 0.6, -0.5), 0.5 * kPi / 180, Vec3(1e5, 1e5, 1e5),
                                           Vec3(0.25, 0.45, 1.0), Vec3(0.9, 0.9, 0.85)),
                     Layout::with_size(LayoutKind::LatLong, 1024), 6);
  return env;
}

Layout target(int kind) {
  switch (kind) {
    case 0: return Layout::with_size(LayoutKind::Cube, 256);
    case 1: return Layout::with_size(LayoutKind::Octahedral, 512);
    default: return Layout::with_size(LayoutKind::Sphere, 512);
  }
}

void BM_OpenCvRemap(benchmark::State& state) {
  const EnvMap& src = source();
  const Layout dst = target(int(state.range(0)));
  cv::Mat mx(dst.height(), dst.width(), CV_32FC1), my(dst.height(), dst.width(), CV_32FC1);
  for (int r = 0; r < dst.height(); ++r)
    for (int c = 0; c < dst.width(); ++c) {
      const auto d = dst.texel_direction(c, r);
      const Vec2 p = d ? src.layout.pixel(*d) : Vec2(-1, -1);
      mx.at<float>(r, c) = float(p.x());
      my.at<float>(r, c) = float(p.y());
    }
  cv::Mat out;
  for (auto _ : state) {
    cv::remap(src.pixels, out, mx, my, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    benchmark::DoNotOptimize(out.data);
  }
  state.SetLabel(to_string(dst.kind()));
  state.counters["texels"] = double(dst.texel_count());
}

void BM_Resample(benchmark::State& state) {
  const EnvMap& src = source();
  const Layout dst = target(int(state.range(0)));
  ResampleOptions options;
  options.supersampling = double(state.range(1));
  for (auto _ : state) {
    EnvMap out = resample(src, dst, options);
    benchmark::DoNotOptimize(out.pixels.data);
  }
  state.SetLabel(to_string(dst.kind()) + ", supersampling " + std::to_string(state.range(1)));
  state.counters["texels"] = double(dst.texel_count());
}

BENCHMARK(BM_OpenCvRemap)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Resample)->ArgsProduct({{0, 1, 2}, {1, 4}})->Unit(benchmark::kMillisecond)->MinTime(0.5);

}  // namespace
}  // namespace rsibr
