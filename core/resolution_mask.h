// The MIP-mask blend's masks (runtime/blend_engine.h, calib/probe/probe.h): which map of a set to trust at
// which level of detail when the maps were measured at different resolutions (a chrome ball 43 px
// across in one photo and 400 px in another, both extracted to the same map size).
//
// A map view's native size nu is the number of texels across its disc where they were measured
// (MapView attribute "nativeSize", e.g. the ball's image diameter in pixels; absent: the map width
// W). Its map holds real detail from level l = max(0, log2(W / nu)) of a MIP pyramid on; finer levels
// are an upsampling. Its mask pyramid (core/mask_pyramid.h) is authored, not filtered:
//
//   m(l)(texel) = min over the level-0 texels it covers of coverage  *  clamp(l - l_native + 1, 0, 1)
//
// so a mask texel says "this map fully covers here and resolves this level of detail". A lookup at
// level of detail lambda reads m trilinearly; a blend of maps i then scales each weight by
// s_i = m_i + 1 - max_j m_j: the sharpest maps wherever they fully cover, the plain blend where none
// does, and a smooth change in between.
#pragma once

#include "formats/map_set.h"
#include "core/mask_pyramid.h"

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

namespace rsibr {

// max(0, log2(W / nu)) of one map view. Throws std::invalid_argument naming the attribute when
// "nativeSize" is not a positive number.
double native_detail_level(const MapView& view);

// Whether a set's maps differ in resolution: their detail levels more than 1/2 apart (a factor sqrt 2).
bool mixed_resolution(const std::vector<double>& detail_levels);

// The mask pyramid above from a CV_32FC1 coverage image (values outside [0, 1] clamped; 0 where the
// map has nothing, e.g. outside the disc).
std::unique_ptr<MaskPyramid> resolution_mask(const cv::Mat& coverage, double detail_level);

}  // namespace rsibr
