// `rsibr process --ball VIEW:BALL=X,Y,R`: one ball of one view given by hand (its image centre and
// radius in pixels, roughly: within ~20%), instead of the detection. The ball is located at that
// guess (calib/balls/ball_locator.h) and used whatever the cross-view checks say.
#pragma once

#include "calib/balls/ball_locator.h"
#include "formats/photo_set.h"

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct BallOverride {
  std::string view, ball;
  BallGuess guess;
};

// Throws std::invalid_argument("--ball '<text>': <problem>") for a malformed text, a view or ball
// the photo set does not list, or a second override of the same view and ball.
std::vector<BallOverride> parse_ball_overrides(const std::vector<std::string>& texts, const PhotoSet& set);

// The override of (view, ball), if any.
std::optional<BallGuess> find_override(const std::vector<BallOverride>& overrides, const std::string& view,
                                       const std::string& ball);

}  // namespace rsibr
