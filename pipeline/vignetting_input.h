// The vignetting the hdr step divides out (hdr/vignetting.h), from what `--vignetting` says:
//   auto   estimated from the photo set's chessboard images (their corners found by mrgingham,
//          their codes made linear by the recovered response), none when it has fewer than 3 boards;
//          without boards, lensfun's profile of the lens the first photo's EXIF names
//          (calib/lens/photo_optics.h lensfun_vignetting), none when lensfun has none
//   none   no correction
//   FILE   a JSON model as vignetting.json holds it (e.g. from a lens database)
// The principal point is the lens model's.
#pragma once

#include "core/lens_model.h"
#include "formats/photo_set.h"
#include "hdr/vignetting.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

// The files the choice reads (the boards for auto, the file for FILE).
std::vector<std::filesystem::path> vignetting_inputs(const PhotoSet& set, const std::string& mode);

// The model and what to report of it ({"model", "estimate": {...}}). Throws std::invalid_argument
// for a FILE that does not hold a model.
Vignetting photo_set_vignetting(const PhotoSet& set, const std::string& mode, const ResponseCurve& curve,
                                const LensModel& lens, nlohmann::json* report);

}  // namespace rsibr
