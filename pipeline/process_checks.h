// What rsibr process refuses before any work (pipeline/process_pipeline.h): every option that names
// a file, a step, a colour space, a BRDF or a pose file is checked first, so a mistyped option
// never costs a merge; then the photo set and the output folder.
#pragma once

#include "formats/photo_set.h"
#include "pipeline/process_pipeline.h"

#include <filesystem>

namespace rsibr {

// Throws std::invalid_argument("<option or file>: <problem>").
void check_process_options(const ProcessOptions& o);

// The photo set (its views, colour space and the --ball overrides against it) and the output
// folder `dir` (absolute): not a file, its parent existing, not the photo folder. Throws
// std::invalid_argument.
void check_process_inputs(const ProcessOptions& o, const PhotoSet& set, const std::filesystem::path& dir);

}  // namespace rsibr
