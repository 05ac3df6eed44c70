// A camera RAW file as the synthetic camera writes it: a DNG (Adobe's Digital Negative, the
// TIFF-based RAW format every RAW reader understands) holding one Bayer mosaic, with the tags a
// reader needs to develop it: the CFA pattern, black and white levels, ColorMatrix1 (XYZ ->
// camera, D65), AsShotNeutral (the camera's white balance) and the exposure (ExposureTime,
// FNumber, ISOSpeedRatings in IFD 0, as TIFF/EP allows). Written with libtiff.
#pragma once

#include "core/vec.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace rsibr {

struct DngInfo {
  std::string make = "rsibr", model = "synthetic camera";
  std::string cfa = "RGGB";                 // the 2x2 pattern from the top-left pixel, row by row
  int black = 0, white = 65535;             // code of no light, code of the sensor's saturation
  Mat3 camera_from_xyz = Mat3::Identity();  // ColorMatrix1 (D65); any scale (readers normalise it)
  Vec3 as_shot_neutral = Vec3::Ones();      // camera RGB of a neutral, the largest 1
  double exposure_s = 0, iso = 100, aperture = 1;
};

// ColorMatrix1 for a sensor whose raw RGB is camera_from_rec709 times linear Rec.709 (D65)
// radiance: camera_from_rec709 * rec709_from_xyz.
Mat3 dng_colour_matrix(const Mat3& camera_from_rec709);

// The Bayer mosaic of a camera-RGB raw image: pixel (x, y) keeps the channel that `cfa` puts
// there. raw: CV_16UC3, RGB, codes in [black, white]. Returns CV_16UC1.
cv::Mat bayer_mosaic(const cv::Mat& raw, const std::string& cfa);

// Writes `mosaic` (CV_16UC1, codes in [black, white], even width and height) as a DNG at `file`
// (atomically: a temporary name, then rename). Throws std::runtime_error("<file>: ...") on I/O
// errors, std::invalid_argument on a bad mosaic, pattern or levels.
void write_dng(const std::filesystem::path& file, const cv::Mat& mosaic, const DngInfo& info);

}  // namespace rsibr
