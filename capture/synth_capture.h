// `rsibr synth`: a synthetic capture with its ground truth, written as two folders under DIR:
//
//   DIR/photos/   a photo set (photoset.yaml, formats/photo_set.h): per view <view>/<view>_bNN.<ext>
//                 (one file per exposure, shortest first, exposure_s/iso/aperture in the YAML) and
//                 chessboards/boardNN.<ext> (the same camera: response, format, white balance)
//   DIR/truth/    truth.yaml (the exposure convention's gain k, full well, read noise, response,
//                 vignetting, white balance, per view the pose, per bracket its exposure and clipped
//                 fraction, per ball its centre and image position, per board its pose),
//                 camera.cameramodel (mrcal), response.csv (code -> relative exposure X/full_well,
//                 per channel), views/<view>_radiance.exr (L at the pixel: after vignetting and white
//                 balance, what a merge recovers as X / (e k)), views/<view>_scene.exr (before them),
//                 maps/<ball>.exr (the true sphere maps, one map-set part per view,
//                 capture/true_sphere_map.h), chessboards/boardNN.txt (true corner pixels, "x y").
//
// Exposure convention (shared with hdr/, capture/sensor_noise.h): X = L e k electrons, e =
// t * iso/100 / N^2. When the scene gives no gain, k is chosen so that the median radiance of the
// first view (mean of R, G, B) at the middle exposure records 18% of the full well (a metered exposure).
//
// The radiance of each view is rendered once; every bracket is derived from it (exposure, noise,
// response), so brackets cost little. DIR must not exist (or be empty); everything is written to a
// temporary folder beside it and renamed at the end, so a failure leaves no partial output.
#pragma once

#include "capture/synth_scene.h"
#include "core/env_map.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace rsibr {

struct SynthReport {
  int views = 0, brackets = 0, chessboards = 0;
  long long pixels_rendered = 0;  // primary samples traced
  double gain = 0;
  double seconds_render = 0, seconds_brackets = 0, seconds_truth = 0, seconds_total = 0;
};

// The environment of the scene (file or pattern), scene-linear, RGB lat-long (or the file's layout).
EnvMap synth_environment(const SynthScene& scene);

SynthReport write_synth_capture(const SynthScene& scene, const std::filesystem::path& out,
                                const std::function<void(double)>& progress = {});

}  // namespace rsibr
