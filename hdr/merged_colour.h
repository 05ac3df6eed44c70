// Colour of a merged image (hdr/merge.h): the camera's linearised RGB taken into the working space
// of the OCIO config (core/colour.h), and a user's white balance, each applied to the radiance and,
// consistently, to its variance. Both the `hdr` verb and `rsibr process` call these.
//
// A linear conversion x' = M x takes the per-channel variances to var(x'_i) = sum_j M_ij^2 var(x_j)
// (the channels' covariances are not kept: the merge estimates none); a gain g_c scales the
// variance by g_c^2.
#pragma once

#include "hdr/merge.h"

#include <opencv2/core.hpp>

#include <string>

namespace rsibr {

// The 3x3 matrix of the linear OCIO conversion `from` -> `to`, from its action on the unit
// colours. Throws std::runtime_error for an unknown colour space or a conversion that is not linear
// (its action on 2 x a unit colour is not twice that on the unit colour).
cv::Matx33f colour_conversion_matrix(const std::string& from, const std::string& to);

// The colour space a view's merged radiance is in: `given` (the user's, or the photo set's) when
// not empty; else for camera RAW (developed to linear Rec.709, hdr/raw_image.h) the config's
// "lin_rec709" when it has one; else empty (the working space).
std::string merged_colour_space(const std::string& given, bool raw);

// `m` from colour space `from` into the config's working space (no-op when `from` is empty or
// the working space itself).
void merged_to_working_space(MergedImage& m, const std::string& from);

// Per-channel gains on the radiance (the camera's white balance kept, the user's applied on top).
void apply_white_balance(MergedImage& m, const cv::Vec3f& gains);

}  // namespace rsibr
