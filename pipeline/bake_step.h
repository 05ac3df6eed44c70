// The `bake` step of rsibr process (pipeline/process_pipeline.h), after sources: computed maps of
// the grey balls from the probe, Lambert of the given albedo, at each captured map's own frames and
// size (so the comparison is texel for texel) -> one map set per grey ball. The integrator is the
// one given, or, with max_error > 0, the cheapest plan/bake_plan.h predicts within that relative RMS
// of the probe's full reference quadrature (planned with the bake's own seed).
#pragma once

#include "pipeline/step_outputs.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace rsibr {

struct BakeGreyBall {
  std::string name;
  std::filesystem::path captured, computed;  // its captured map set (read), its computed one (written)
};

struct BakeStep {
  std::filesystem::path probe;  // probe.exr
  std::vector<BakeGreyBall> balls;
  double albedo = 0.18;
  std::string method = "mis";
  int samples = 128;
  double max_error = 0;  // > 0: planned instead of method and samples
  std::uint64_t seed = 0;
  std::function<void(const std::string&)> log;  // the plan's choice (empty: silent)
};

// The summary: the material, per ball its views, the method (and the plan when planned).
StepOutputs run_bake_step(const BakeStep& s);

}  // namespace rsibr
