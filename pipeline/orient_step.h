// The `orient` step of rsibr process (pipeline/process_pipeline.h), after lens: world_from_cam per
// view, solved from the chrome ball's reflected features (calib/orientation/view_orientation.h; world
// +Y up estimated from the views, or `up` given in the first camera's frame), or given (--poses:
// the file's chrome balls, refined here by the features with the rotations held when the file has
// none; a first-view file levelled by the estimated up). The chrome balls are the balls step's
// (calib/balls/shoot_balls.h), refitted through the lens: nothing is searched again. The caller
// writes the poses; the pairs' pictures go to `pictures`.
#pragma once

#include "calib/balls/shoot_balls.h"
#include "calib/orientation/point_pairs.h"
#include "calib/orientation/pose_file.h"
#include "calib/view_image.h"
#include "core/lens_model.h"
#include "core/vec.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct OrientStep {
  const LensModel* lens = nullptr;  // the lens step's lens
  std::vector<std::string> views;   // the photo set's views, in order
  // A view's merged image on the lens's canvas (read only when the features are needed).
  std::function<ViewImage(const std::string& view)> read_view;
  ShootBalls found;                  // the balls step's findings (every view)
  std::optional<PoseSet> given;      // --poses, read (every view has a pose); none: solved
  std::string given_file;            // its path (for the summary)
  std::optional<PointPairs> points;  // points picked by hand in the chrome balls
  std::optional<Vec3> up;            // world up in the first camera's frame
  bool estimate_up = true;           // without `up`: estimated from the views
  // Where each pair's matches are drawn (A--B.png, calib/orientation/pair_matches_picture.h); the
  // summary names them relative to its parent. Empty: none drawn.
  std::filesystem::path pictures;
};

struct OrientedViews {
  PoseSet poses;                                // in the set's order, only the views oriented
  std::vector<std::filesystem::path> pictures;  // the pairs' pictures written
  nlohmann::json summary;                       // source, gauge, views, solve, left out, notes, world up
};

// Throws std::invalid_argument for bad input (a view the balls step did not see), and what the
// solve throws; `failed`, when given, then receives what the solve saw before it stopped (views
// left out, notes, features, pairs and their pictures) for the step's failure record.
OrientedViews run_orient_step(const OrientStep& s, nlohmann::json* failed = nullptr);

}  // namespace rsibr
