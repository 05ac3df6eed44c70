// The `hdr` step of rsibr process (pipeline/process_pipeline.h), after calibrate: the camera's
// response recovered once (from the views with brackets; held-out error picks the model), the
// vignetting (pipeline/vignetting_input.h), and every view's merge with it divided out
// (hdr/photo_set_merge.h, merge_view_radiance: the same merge as rsibr hdr) -> OUT/<view>.exr,
// OUT/response.json, OUT/vignetting.json. Or the stage swapped for given linear images (the truth
// of a synthetic capture, for the error budget), written as merged views with zero variance and
// no flags.
#pragma once

#include "formats/photo_set.h"
#include "pipeline/step_outputs.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct HdrStep {
  const PhotoSet* set = nullptr;
  std::string vignetting = "auto";  // "auto", "none" or a JSON file (pipeline/vignetting_input.h)
  std::filesystem::path lens;       // the calibrate step's lens (the vignetting's principal point)
  std::string input_colour_space;   // the option; empty: the photo set's camera.colour_space
  std::filesystem::path out;        // the hdr folder
  bool progress = false;
};

// The files written; the summary: the response, its candidates, the vignetting, per view its
// clipped, ghost and alignment figures.
StepOutputs run_hdr_step(const HdrStep& s);

// Per view of `set`, its given linear image in `folder`: <view>_radiance.exr, else <view>.exr.
// Throws std::invalid_argument naming the folder and the files looked for when neither exists.
std::vector<std::filesystem::path> given_radiance_files(const PhotoSet& set, const std::string& folder);

// The given images (one per view of `set`, in order) as merged views in `out`.
StepOutputs run_given_radiance_step(const PhotoSet& set, const std::vector<std::filesystem::path>& files,
                                    const std::string& folder, const std::filesystem::path& out);

// The bracket of a view that its registration left furthest from the middle one (the largest
// disagreement of the threshold bitmaps after it), for an error about a ghost: "FILE (moved X,Y px;
// P% of its bitmap disagrees)", or "" when the hdr step's summary does not tell.
std::string suspect_bracket(const std::string& view, const nlohmann::json& hdr_summary);

}  // namespace rsibr
