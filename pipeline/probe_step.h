// The `probe` step of rsibr process (pipeline/process_pipeline.h), after extract: the chrome maps
// blended by confidence into a lat-long probe (calib/probe/probe.h), the chrome ball's Fresnel
// divided out -> OUT (probe-measured.exr). A probe that saw under 10% of the sphere stops the run (a
// chrome ball sees most of it from one view: the lens or the ball is wrong). Or the stage swapped
// for a given environment (the truth, for the error budget), resampled (area-weighted,
// core/resample.h) to the probe's size.
#pragma once

#include "pipeline/step_outputs.h"

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct ProbeStep {
  std::vector<std::filesystem::path> chrome_maps;  // the extract step's captured-<chrome ball>.exr
  int width = 0;                                   // lat-long width
  std::string chrome_fresnel;                      // the chrome ball's Fresnel spec (YAML text)
  std::string given;                               // an environment file instead of the maps; empty: none
  std::filesystem::path out;
};

// The summary: views, width, covered, well seen (summed confidence >= 1/2) and clipped fractions,
// the Fresnel divided out.
StepOutputs run_probe_step(const ProbeStep& s);

}  // namespace rsibr
