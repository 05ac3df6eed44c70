// The `lens` step of rsibr process (pipeline/process_pipeline.h), between balls and orient: the
// calibrate step's lens, its focal length refined from the balls' outlines (calib/lens/outline_focal.h)
// when it came from the photos' metadata (a pinhole from the EXIF, or lensfun's profile), whose
// focal length is nominal and uncertain by a few percent. The listed balls of every view, as the
// balls step found them through the metadata's lens, give the outline estimate; the metadata's is
// its prior (Gaussian, the stated sigma), so
//   f = (f0 / s0^2 + fo / so^2) / (1 / s0^2 + 1 / so^2),   sigma = (1 / s0^2 + 1 / so^2)^(-1/2).
// An outline estimate more than 4 combined sigmas from the prior is not used (the balls or the
// metadata are wrong; the summary says which numbers disagree). With no focal length in the
// metadata (source "outlines") the outlines alone give it, searched from a quarter to four times
// the calibrate step's guess; when they cannot, the step is an error that asks for --lens. A
// measured lens (chessboards, --lens, the photo set's model) passes through unchanged.
// DIR/lens.cameramodel is the lens every later step uses. Views that are crops of the ball (every
// view's chrome ball fills its frame) get the far-camera model instead (calib/lens/far_camera.h),
// whatever the metadata says: their EXIF focal length belongs to the uncropped frame; views of
// different sizes are an error otherwise.
#pragma once

#include "calib/balls/shoot_balls.h"
#include "core/lens_model.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct LensStep {
  std::filesystem::path calibrated;  // the calibrate step's camera.cameramodel
  std::string source;                // its source: "exif" and "lensfun" are refined, "outlines" measured
  double prior_sigma_relative = 0;   // its focal length's stated 1 sigma (relative)
  std::string metadata_note;         // source "outlines": what the metadata lacked (for the error)
  // The balls step's findings (calib/balls/shoot_balls.h): every view's size and balls, located
  // through the calibrated lens (a pinhole of the view's diagonal for a view of another size).
  ShootBalls balls;
  bool refine = true;         // false: the calibrated lens unchanged
  std::filesystem::path out;  // lens.cameramodel
  // Where the balls step drew each view's candidates (<view>.png), named in the errors that ask for
  // --ball; empty: none drawn.
  std::filesystem::path pictures;
};

// Writes `out` atomically and returns the step's summary.
nlohmann::json run_lens_step(const LensStep& step);

}  // namespace rsibr
