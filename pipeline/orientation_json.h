// What the orientation saw, as JSON for the orient step's record and `rsibr orient --json`.
#pragma once

#include "calib/orientation/view_orientation.h"

#include <nlohmann/json.hpp>

#include <vector>

namespace rsibr {

// One object per pair of views: the rotation search (score, runner-up, overlap, angle), the
// features each view had, the matches, the tracks both observe and the inliers among them, and how
// far the solved rotation lies from the searched one.
nlohmann::json pair_orientation_json(const std::vector<PairOrientation>& pairs);

}  // namespace rsibr
