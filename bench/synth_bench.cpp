// Synthetic capture (capture/synth_capture.h): one view of the on-set rig at 2000 x 1500 through an
// OPENCV8 lens, 4 samples per pixel (2 x 2 stratified), 7 brackets 2 EV apart, each exposed (shot
// and read noise, response) and PNG-encoded in memory. rsibr renders the linear radiance once and
// derives the brackets from it; the baseline, in the same run, renders every bracket from scratch.
// Case 0: the whole bracket; case 1: the one render alone; case 2: the 7 exposures + encodes alone.
#include "capture/camera_poses.h"
#include "capture/camera_response.h"
#include "capture/rig_renderer.h"
#include "capture/sensor_noise.h"
#include "capture/synth_capture.h"
#include "formats/image_codecs.h"

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

namespace rsibr {
namespace {

const char* kScene = R"(
rsibr_synth: 1
seed: 1
environment: {pattern: sun_and_sky, size: 512, sun_direction: [0.4, 0.7, 0.6], sun_rgb: [20000, 19000, 17000]}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.075, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.075, 1.3, 0]}
camera:
  width: 2000
  height: 1500
  lens: {model: LENSMODEL_OPENCV8, focal_px: 2200, distortion: [-0.12, 0.03, 0.0004, -0.0003, 0, 0.01, 0, 0.005]}
  supersampling: 2
exposure: {middle_s: 0.004, count: 7, step_ev: 2}
views: [{plan: ring, count: 1, elevation_deg: 8, distance_m: 1.6}]
)";

struct Setup {
  SynthScene scene = parse_synth_scene(kScene, "synth_bench", ".");
  EnvMap env = synth_environment(scene);
  RigRenderer renderer{scene, env};
  CameraPose pose = plan_camera_poses(scene).front();
  RayTable rays{scene.camera.lens};
  CameraResponse response{"srgb"};
  SensorNoise noise{5e7, 2e4, 3};
};

Setup& setup() {
  static Setup s;
  return s;
}

cv::Mat render(Setup& s) {
  RigRenderOptions o;
  o.supersampling = 2;
  return s.renderer.render(s.pose, s.scene.camera.lens, s.rays, o);
}

std::size_t expose_and_encode(Setup& s, const cv::Mat& L, int bracket) {
  const double e = s.scene.exposure.times()[std::size_t(bracket)] / 64.0;
  cv::Mat codes = expose_bracket(L, e, s.noise, s.response, 255, 1, std::uint64_t(bracket));
  cv::Mat bgr;
  cv::cvtColor(codes, bgr, cv::COLOR_RGB2BGR);
  bgr.convertTo(bgr, CV_8U);
  std::vector<uchar> bytes;
  rsibr::encode_image(".png", bgr, bytes);
  return bytes.size();
}

void BM_SynthBracket(benchmark::State& state) {
  Setup& s = setup();
  const int mode = int(state.range(0));
  const cv::Mat prerendered = mode == 2 ? render(s) : cv::Mat();
  for (auto _ : state) {
    const cv::Mat L = mode == 2 ? prerendered : render(s);
    if (mode != 1)
      for (int b = 0; b < 7; ++b) benchmark::DoNotOptimize(expose_and_encode(s, L, b));
    benchmark::DoNotOptimize(L.data);
  }
  state.SetLabel(mode == 0 ? "render once + 7 brackets" : mode == 1 ? "the render alone" : "7 brackets alone");
}
BENCHMARK(BM_SynthBracket)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(2);

void BM_SynthBracketFromScratch(benchmark::State& state) {
  Setup& s = setup();
  for (auto _ : state)
    for (int b = 0; b < 7; ++b) {
      const cv::Mat L = render(s);
      benchmark::DoNotOptimize(expose_and_encode(s, L, b));
    }
}
BENCHMARK(BM_SynthBracketFromScratch)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace rsibr
