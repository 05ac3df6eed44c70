// A diffuse (Lambertian) ball's radiance depends on its normal only, so every view that sees a
// normal must see the same value there. What differs in one view alone is not the environment's
// light but that view's own: the photographer's shadow or body, which move with the camera. Each
// texel of each view's grey map is compared with the median, at the same world normal, of its own
// value and the other views' (their maps sampled bilinearly there, where they see it with
// confidence): a texel more than `max_stops` off in luminance (with at least `min_others` other
// views, so that the median is of three or more) gets confidence 0. A view with more than `max_masked` of its judged texels masked is left out (its
// confidence cleared: reported as inconsistent with the other views), the worst first and the rest
// judged again without it (a shadowed view would bias the medians of its neighbours).
//
// Maps: captured sphere maps of one Lambertian ball (warp "normal", orthographic indexing), one
// per view, in one world frame (formats/map_set.h); texel p's world normal is world_from_view *
// g_normal(p).
#pragma once

#include "formats/map_set.h"

#include <vector>

namespace rsibr {

struct LambertConsensusOptions {
  double max_stops = 0.12;
  int min_others = 2;
  double min_confidence = 0.5;  // texels below it neither judged nor used as judges
  double max_masked = 0.5;
};

struct LambertConsensusView {
  int judged = 0, masked = 0;  // confident texels with enough other views, and those masked
  double median_stops = 0;     // median deviation of the judged texels (this view against the others)
  bool left_out = false;
};

// Changes the confidence channels in place; one entry per view.
std::vector<LambertConsensusView> mask_lambert_inconsistencies(std::vector<MapView>& views,
                                                               const LambertConsensusOptions& options = {});

}  // namespace rsibr
