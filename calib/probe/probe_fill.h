// Directions no view saw (behind the ball, its stand, the masked camera), filled so that a lat-long
// probe is usable in a renderer. The filled texels carry no confidence: the probe's confidence and
// flags channels say which they are (calib/probe/probe.h, ProbeFlag).
//
// Method: push-pull (a pyramid of solid-angle-weighted means of the trusted texels; going back down,
// each texel blends its own mean with the coarser level's in proportion to how much of it was
// known, so a hole takes a smooth interpolation of its rim, large holes from coarser levels). The
// means are of log radiance: a sun or lamp beside a hole would otherwise spread its energy over the
// whole hole (an arithmetic mean of one texel at 1e6 among a hundred at 1 is 1e4; the geometric
// mean is 1.15). Texels at or below `floor` x the trusted texels' median take part as that floor.
#pragma once

#include "core/env_map.h"

#include <opencv2/core.hpp>

namespace rsibr {

// Fills the lat-long `env`'s texels where `fill` is non-zero from those where `trusted` is non-zero
// (both CV_8UC1 of the map's size); every other texel is left bit for bit. Returns the filled
// solid-angle fraction of the sphere. Throws std::invalid_argument when the map is not a 3-channel
// lat-long, the masks do not match, or there is something to fill and no trusted texel.
double fill_unseen(EnvMap& env, const cv::Mat& trusted, const cv::Mat& fill, double floor = 1e-4);

}  // namespace rsibr
