// The `compare` step of rsibr process (pipeline/process_pipeline.h), after bake: each grey ball's
// captured maps against its computed ones (compare/map_compare.h), with the same JSON and pictures
// as rsibr compare (compare/comparison_report.h) -> OUT/<ball>/<view>.png beside the summary. A view
// whose ball has no trusted texel (hidden behind another ball, or not found) cannot be compared: it
// is left out and listed.
#pragma once

#include "pipeline/step_outputs.h"

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct CompareBall {
  std::string name;
  std::filesystem::path captured, computed;  // map sets, one computed view per captured one, in order
};

struct CompareStep {
  std::vector<CompareBall> balls;
  std::filesystem::path out;  // the compare folder: one folder of pictures per ball
};

// The summary: per ball the comparison's JSON, each view's image and picture, the views left out.
StepOutputs run_compare_step(const CompareStep& s);

}  // namespace rsibr
