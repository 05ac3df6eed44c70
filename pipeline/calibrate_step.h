// The `calibrate` step of rsibr process (pipeline/process_pipeline.h), the first: the lens model
// -> OUT (a .cameramodel), from one source, in this order of preference:
//   given        --lens FILE, copied
//   chessboards  the photo set's chessboards -> mrcal, the model chosen by cross-validation among
//                kCalibrateModels (calib/lens/intrinsics.h)
//   photo set    the photo set's camera.model, copied
//   exif         the photos' metadata (calib/lens/photo_optics.h): lensfun's distortion profile of
//                the camera and lens the EXIF names, else a pinhole of the EXIF focal length, with
//                its stated sigma; with no focal length at all (source "outlines"), a pinhole of the
//                image's diagonal that the lens step measures from the balls' outlines
#pragma once

#include "formats/photo_set.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

inline const std::vector<std::string> kCalibrateModels = {"LENSMODEL_PINHOLE", "LENSMODEL_OPENCV4",
                                                          "LENSMODEL_OPENCV8"};

struct CalibrateStep {
  const PhotoSet* set = nullptr;
  std::string photoset;        // its path, for errors
  std::string source;          // "given", "chessboards", "photo set" or "exif"
  std::filesystem::path file;  // given: the lens; photo set: its model; exif: the first view's first bracket
  std::filesystem::path out;   // camera.cameramodel
  bool progress = false;
};

// Writes `out` and returns the step's summary (source, model, intrinsics; chessboards: the fit's
// RMS, the boards found and missed, every model's held-out RMS; exif: the focal length, its sigma
// and where it came from).
nlohmann::json run_calibrate_step(const CalibrateStep& st);

}  // namespace rsibr
