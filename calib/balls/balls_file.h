// DIR/balls.json, the balls step's findings (calib/balls/shoot_balls.h), as later steps and users
// read them:
//
//   {"format": "rsibr-balls", "version": 1,
//    "balls": [{"name", "kind", "diameter_m" (or null)}],       the listed balls
//    "views": [{"name", "size": [w, h],
//               "lens": {"model", "intrinsics", "size"},        what the cones were fitted through
//               "balls": [{"ball", "kind", "status", "candidate", "note",  per listed ball
//                          "centre_px", "radius_px", "confidence",         when found
//                          "offset_from_chrome"}],
//               "candidates": [{"centre_px", "radius_px", "cone": {"axis", "half_angle"},
//                               "rms_px", "inliers", "lines_inside", "outline_px": [x0, y0, ...],
//                               "residual_px", measures...}]}]}
//
// confidence: the share of the ball's visible outline that shows an edge on its fitted circle
// (the outline support, at most 1). offset_from_chrome: the ball's centre minus the view's chrome
// ball's, camera frame (x right, y down, z forward), in chrome-ball radii, when the view's chrome
// ball is found and both diameters are listed (the scale between the balls); null otherwise. It is
// the rig offset before any rotation is known (world offset = world_from_cam times it). Numbers
// are written to round-trip exactly, so a step reading the file sees what the balls step saw.
#pragma once

#include "calib/balls/shoot_balls.h"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace rsibr {

// Writes atomically (a temporary name, then rename).
void write_balls_file(const std::filesystem::path& file, const ShootBalls& balls);

// Throws std::invalid_argument("<file>: <problem>") for a file that is not such a file (a missing
// field, a candidate index out of range, a status not listed above).
ShootBalls read_balls_file(const std::filesystem::path& file);

// Throws std::invalid_argument("<what>: ...") when the file's balls are not `listed` (names, kinds
// and diameters, in order; none listed: the one chrome ball find_shoot_balls assumes).
void check_listed_balls(const ShootBalls& balls, const std::vector<ListedBall>& listed, const std::string& what);

// The balls file's JSON without the candidates (a step's summary of what was found).
nlohmann::json balls_summary_json(const ShootBalls& balls);

}  // namespace rsibr
