// Choosing the warp of a blend for an error budget: each candidate warp's destination map at the
// requested view is compared with the exact warp's (the blend's definition, runtime/blend.h) and
// timed through one blend engine (tables built before timing, as a viewer or turntable reuses them);
// the fastest within the budget is chosen, the exact warp when none is.
//
// The error: sqrt(sum |B_w - B_exact|^2 / sum |B_exact|^2) over the texels where the exact blend's
// weight is > 0 (RGB lengths). It is the warp's approximation alone; how far the set itself is from
// a direct bake is the bake's budget (plan/bake_plan.h).
#pragma once

#include "formats/map_set.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/make_warp.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace rsibr {

struct WarpMeasure {
  WarpSettings warp;
  double error = 0;    // against the exact warp
  double seconds = 0;  // one destination map, the fastest of three
  bool meets = false;
};

struct WarpPlan {
  double max_error = 0;
  std::vector<WarpMeasure> measured;  // exact first, then the candidates as given
  WarpMeasure chosen;
  nlohmann::json to_json() const;
};

// Precomputed, tessellated with 8, 16 and 32 rings, double-indirection about `axis`.
std::vector<WarpSettings> default_warp_candidates(const Vec3& axis);

// Throws std::invalid_argument for a budget outside (0, 1) and what the blend throws.
WarpPlan plan_warp(const MapSet& set, const ViewSet& views, const Vec3& view, const Vec3& up, int width, int height,
                   double max_error, const std::vector<WarpSettings>& candidates, const BlendRule& rule = {});

}  // namespace rsibr
