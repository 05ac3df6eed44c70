// Camera RAW files (CR2, CR3, NEF, ARW, DNG, RAF, ORF, RW2, PEF, ... as LibRaw reads them),
// developed to linear codes the merge uses with the identity response:
//
//   LibRaw     black level(s) subtracted, white balance multipliers m_c applied with the smallest
//              1 (the camera's as-shot balance unless given), scaled so that the white level of
//              that channel is code 65535, every channel clipped there (dcraw's highlight mode
//              0), demosaiced (AHD), in the camera's own RGB, no gamma, no automatic brightness,
//              the white level never adjusted to the data (adjust_maximum_thr 0: brackets that do
//              not reach it keep the same scale)
//   here       out = rgb_cam * camera (LibRaw's camera -> linear sRGB / Rec.709 D65 matrix, rows
//              summing to 1, so the balanced neutral stays neutral), clamped to [0, 65535]; a
//              clipped camera channel sets its output channel to 65535; the saturation mask: a
//              camera channel clipped at the pixel or within 2 px (the demosaic spreads a clipped
//              sample, and the values it makes there are neither data nor a bound)
//
// Below 65535 and outside the mask the codes are proportional to scene-linear Rec.709 radiance
// times exposure; the merge leaves masked pixels out of the bracket (BracketSet::saturated).
#pragma once

#include "core/vec.h"

#include <opencv2/core.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>

namespace rsibr {

// By extension, case-insensitive: the RAW formats LibRaw reads.
bool is_raw_file(const std::filesystem::path& file);

struct RawOptions {
  // White balance multipliers on the camera's channels (R, G, B; any scale). Nullopt: the file's
  // as-shot balance.
  std::optional<Vec3> white_balance;
};

struct RawInfo {
  std::string make, model;
  int black = 0;                      // the file's black level (smallest over the channels), raw units
  int white = 0;                      // the file's white level, raw units
  Vec3 white_balance = Vec3::Ones();  // multipliers applied, the smallest 1
  Mat3 rgb_from_camera = Mat3::Identity();
  double exposure_s = 0, iso = 0, aperture = 0;  // from the file (0 when absent)
  double saturated_fraction = 0;                 // pixels flagged saturated
};

struct RawImage {
  cv::Mat codes;      // CV_16UC3, RGB, linear
  cv::Mat saturated;  // CV_8UC1, 255 where the sensor saturated (see above)
  RawInfo info;
};

// Throws std::runtime_error("<file>: ...") when LibRaw cannot open, unpack or develop the file.
RawImage read_raw_image(const std::filesystem::path& file, const RawOptions& options = {});

// The developing step after LibRaw, exposed for tests: camera (CV_16UC3, white-balanced camera
// RGB, 65535 = clipped) -> codes, and the saturation mask into `saturated` (see above).
cv::Mat camera_to_output_codes(const cv::Mat& camera, const Mat3& rgb_from_camera, cv::Mat& saturated);

}  // namespace rsibr
