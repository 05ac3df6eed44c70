// In-camera processing of a consumer camera, from the sensor's raw signal to the codes of its
// JPEG or PNG, in the order camera engines apply it:
//
//   raw            r_c = X_c / full_well in [0,1]          (sensor_noise.h expose_raw: electrons
//                                                            mu_c = L_c e k s_c, sensitivity s)
//   white balance  w_c = min(1, g_c r_c)                  (gains g on the raw channels; every
//                                                            channel clips at 1 after them)
//   colour matrix  m = clamp(M w, 0, 1)                   (camera RGB -> output RGB)
//   tone curve     round(f(m_c) * max_code)                (camera_response.h, e.g. filmic: the
//                                                            same curve in every channel)
//   compression    JPEG at a chosen quality (libjpeg through OpenCV: 4:2:0 chroma, 8x8 DCT)
//
// M's rows sum to 1, so a grey after white balance stays grey. Given a saturation s it is
//   M = s I + (1 - s) 1 y^T,  y = (0.2126, 0.7152, 0.0722) (Rec.709 luminance):
// colours move away from their luminance by s, luminance itself is kept. The automatic white
// balance is g_c = max(s) / s_c (the smallest gain 1): a neutral scene radiance records equal
// codes in every channel.
//
// What a merge of such brackets can recover is the linear output before clipping and the tone
// curve, m / e = M (g . s . L) k / full_well per unit exposure (linear_output below times
// k / full_well): linear in L wherever nothing clipped, and neutral for a neutral L.
#pragma once

#include "capture/camera_response.h"
#include "capture/sensor_noise.h"
#include "core/vec.h"

#include <opencv2/core.hpp>

#include <optional>

namespace rsibr {

struct CameraProcessing {
  Vec3 sensitivity = Vec3::Ones();    // s: raw channel sensitivities (the sensor's colour)
  std::optional<Vec3> white_balance;  // g; nullopt: automatic, max(s) / s_c
  double saturation = 1.0;            // s of M when no matrix is given
  std::optional<Mat3> colour_matrix;  // M (rows summing to 1 keep greys grey)

  Vec3 gains() const;   // g
  Mat3 matrix() const;  // M
};

// Raw (CV_64FC3, X / full_well, RGB) -> codes (CV_16UC3, RGB, <= max_code): white balance, clip,
// matrix, clip, tone curve, rounding (no compression; jpeg_compress does that).
cv::Mat process_raw(const cv::Mat& raw, const CameraProcessing& p, const CameraResponse& response, int max_code);

// The linear output a merge recovers (per unit exposure, in units of k / full_well): M (g . s . L)
// for scene radiance L (CV_32FC3, RGB), unclipped. CV_32FC3.
cv::Mat linear_output(const cv::Mat& radiance, const CameraProcessing& p);

// 8-bit codes (CV_16UC3 or CV_8UC3, RGB, values <= 255) through a JPEG encoder at `quality` (1..100)
// and back: what a camera's JPEG file decodes to. Returns CV_16UC3, RGB. Deterministic (libjpeg's
// integer DCT).
cv::Mat jpeg_compress(const cv::Mat& codes, int quality);

// One bracket through the whole camera: expose_raw (sensitivities from p), process_raw, then
// jpeg_compress when jpeg_quality > 0 (8-bit only). CV_16UC3 RGB codes.
cv::Mat camera_bracket(const cv::Mat& radiance, double e, const SensorNoise& noise, const CameraProcessing& p,
                       const CameraResponse& response, int max_code, int jpeg_quality, std::uint64_t seed,
                       std::uint64_t stream);

}  // namespace rsibr
