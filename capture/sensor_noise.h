// The sensor model shared with hdr/ (the exposure convention of the capture and merge stages):
//
//   mean electrons  mu = L * e * k      L: scene-linear radiance reaching the pixel (after
//                                       vignetting and white balance), e: relative exposure
//                                       (BracketPhoto::relative_exposure(): t * iso/100 / N^2),
//                                       k: the camera gain (electrons per unit radiance-exposure)
//   recorded        X = clamp(P + R, 0, full_well),  P ~ Poisson(mu),  R ~ Normal(0, read_noise^2)
//   code            round(f_c(X / full_well) * max_code)   (capture/camera_response.h)
//
// Randomness: every draw comes from a counter-based stream keyed by (seed, stream id), so results
// do not depend on the thread count or the order pixels are visited.
#pragma once

#include "bake/integrator.h"
#include "capture/camera_response.h"
#include "core/vec.h"

#include <opencv2/core.hpp>

#include <cstdint>

namespace rsibr {

struct SensorNoise {
  double gain = 1.0;        // k, electrons per unit of L * e
  double full_well = 2e4;   // electrons
  double read_noise = 3.0;  // electrons, standard deviation
};

using NoiseRng = integrator_detail::TexelRng;

// A Poisson variate of mean mu >= 0: multiplication method below mu = 10, Hormann's PTRS
// (transformed rejection with squeeze, 1993; numpy's algorithm) above. Exact for every mu.
double sample_poisson(double mu, NoiseRng& rng);
// A standard normal variate (Box-Muller, one of the pair).
double sample_normal(NoiseRng& rng);

// The recorded electrons X for mean mu (see above).
double record_electrons(double mu, const SensorNoise& noise, NoiseRng& rng);

// The codes of one bracket: `radiance` is L at each pixel (CV_32FC1 or CV_32FC3, RGB), e the
// relative exposure, max_code 255 (8-bit) or 65535 (16-bit). Pixel i draws from the stream
// NoiseRng(seed, stream * 2^40 + i), channels in order; a single channel uses the G response.
// Returns CV_16UC(channels), RGB order, every value <= max_code.
cv::Mat expose_bracket(const cv::Mat& radiance, double e, const SensorNoise& noise, const CameraResponse& response,
                       int max_code, std::uint64_t seed, std::uint64_t stream);

// The raw signal of one bracket before any response: X / full_well per channel (CV_64FC3, RGB, in
// [0, 1]) for mean electrons mu_c = L_c * e * k * sensitivity_c (a sensor's per-channel colour
// response; ones: as expose_bracket). Same streams and draws as expose_bracket, so with unit
// sensitivities round(f(raw) * max_code) gives expose_bracket's codes. `radiance` CV_32FC3.
cv::Mat expose_raw(const cv::Mat& radiance, double e, const SensorNoise& noise, const Vec3& sensitivity,
                   std::uint64_t seed, std::uint64_t stream);

}  // namespace rsibr
