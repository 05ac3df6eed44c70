// The `sources` step of rsibr process (pipeline/process_pipeline.h), between probe and bake: the
// chrome maps blended again (calib/probe/probe.h, the probe step's settings) for the texels clipped in
// every view that saw them, the light missing there recovered from the grey (and glossy) balls
// (lights/recovered_probe.h) and written into DIR/probe.exr, the probe the bake and the render
// use. Texels clipped in every view and not recovered keep their lower bound, and directions no
// view saw are filled (calib/probe/probe_fill.h); probe.exr's `confidence` and `flags` channels say which
// texels are which (calib/probe/probe.h, ProbeFlag).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct LightSourcesStep {
  std::vector<std::filesystem::path> chrome;                                // captured chrome map sets
  std::vector<std::pair<std::string, std::filesystem::path>> grey, glossy;  // (ball name, captured map set)
  std::string glossy_brdf;         // the glossy balls' BRDF spec; empty: glossy balls unused
  std::filesystem::path measured;  // the probe step's output (the probe as the chrome balls saw it)
  std::filesystem::path out;       // probe.exr
  int probe_width = 256;
  std::string chrome_fresnel;
  double grey_albedo = 0.18;
  bool recover = true;
  bool fill = true;          // directions no view saw filled (calib/probe/probe_fill.h); false: they stay 0
  bool given_probe = false;  // the probe step used a given environment: nothing to recover
  std::uint64_t seed = 0;
};

// Writes `out` atomically and returns the step's summary (lights/recovered_probe.h), with
// "glossy_used" and, for a given probe, "given": true.
nlohmann::json run_light_sources_step(const LightSourcesStep& step);

}  // namespace rsibr
