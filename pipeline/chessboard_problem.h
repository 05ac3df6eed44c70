// The calibration problem of a photo set: the chessboard corners (mrgingham, calib/lens/intrinsics.h)
// of every image listed under chessboards: in photoset.yaml, shared by rsibr calibrate and the
// calibrate step of rsibr process.
#pragma once

#include "calib/lens/intrinsics.h"
#include "formats/photo_set.h"

#include <functional>
#include <string>
#include <vector>

namespace rsibr {

// `name` names the photo set in errors. Images where no board is found go to `missed` (file
// names). Throws std::invalid_argument("<name>: ...") when the set lists no chessboards, the grid
// is not square, the images differ in size, or fewer than 4 boards are found (2 per
// cross-validation half); std::runtime_error("<image>: cannot read the image").
IntrinsicsProblem chessboard_problem(const PhotoSet& set, const std::string& name,
                                     std::vector<std::string>* missed = nullptr,
                                     const std::function<void(double)>& progress = {});

}  // namespace rsibr
