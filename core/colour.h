// Colour management: the OpenColorIO config, colour-space conversion, display encoding and
// working-space matrices for EXR chromaticities.
//
// Convention: images are scene-linear float radiance in the working space (the config's
// `scene_linear` role; with the embedded config, linear Rec.709 primaries, D65 white), stored as
// cv::Mat CV_32FC3 in RGB channel order.
#pragma once

#include <string>

#include <Eigen/Core>
#include <OpenColorIO/OpenColorIO.h>
#include <OpenEXR/ImfChromaticities.h>
#include <opencv2/core/mat.hpp>

namespace rsibr {

// The OCIO config: the file named by $OCIO when that is set and non-empty, else the config
// compiled into the library (core/data/ocio/config.ocio). Loaded once and cached (thread-safe).
// Throws std::runtime_error naming the path when $OCIO's file cannot be loaded or is invalid.
OCIO_NAMESPACE::ConstConfigRcPtr colour_config();

// Name of the colour space of the config's `scene_linear` role (the working space).
// Throws std::runtime_error when the config has no such role.
std::string working_space();

// Converts `rgb` (CV_32FC3 RGB, or CV_32FC4 RGBA with alpha untouched) in place from colour space
// `from` to `to` (colour-space or role names of colour_config()). No-op on an empty image.
// Throws std::runtime_error naming the colour space when one is unknown, or on another type.
void convert_colour_space(cv::Mat& rgb, const std::string& from, const std::string& to);

// Display encoding for viewing / PNG export: scales `linear_rgb` (CV_32FC3 RGB, or CV_32FC4 whose
// alpha is ignored, in the working space) by 2^exposure_stops, applies the config's display/view
// transform (empty names: the config's default display and its default view), and quantises to
// CV_8UC3 in **BGR** order, ready for cv::imwrite. Out-of-range results clamp to [0, 255]; NaN
// maps to 0, +Inf to 255, -Inf to 0. Throws std::runtime_error for an unknown display or view.
cv::Mat display_encode(const cv::Mat& linear_rgb, float exposure_stops, const std::string& display = "",
                       const std::string& view = "");

// display_encode's transform alone, in place, unquantised: CV_32FC3 working-space RGB (finite) to
// the display's encoded values (0..1 in range). Throws std::runtime_error for an unknown display or
// view, or another image type.
void apply_display_transform(cv::Mat& rgb, const std::string& display = "", const std::string& view = "");

// 3x3 matrix taking linear RGB with the given primaries and white (e.g. an EXR `chromaticities`
// attribute) to the working space's linear Rec.709 primaries with D65 white, adapting the white
// with the Bradford CAT when it differs from D65. Acts on column vectors: working = M * rgb.
// Maps (1,1,1) to (1,1,1). Identity (to ~1e-7) for Rec.709/D65 input.
Eigen::Matrix3d working_from_chromaticities(const Imf::Chromaticities& c);

// Drops the cached config so the next colour_config() reloads it (e.g. after changing $OCIO).
// For tests only.
void reset_colour_config_for_testing();

}  // namespace rsibr
