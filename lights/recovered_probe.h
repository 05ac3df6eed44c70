// The whole recovery on an assembled probe (calib/probe/probe.h): its clipped regions
// (lights/clipped_regions.h), the sources solved from the grey and glossy balls
// (lights/source_recovery.h), written into a copy of the probe (lights/probe_sources.h) with their
// provenance in its header, and a JSON summary for --json and the report:
//
//   clipped_fraction     solid-angle fraction of the sphere clipped in every chrome view that saw it
//   regions[]            each region: direction, azimuth/elevation, solid angle, radius, lower bound
//                        of its power, recovered (bool), note (why not)
//   sources[]            lights/probe_sources.h's objects
//   notes[]              one line per region not recovered
//   measured_integral    int L dw of the probe as measured (RGB)
//   recovered_power      sum of the sources' powers (RGB), and its sigma (root sum of squares)
//   missing_fraction     recovered / (measured + recovered) per channel: the share of the final
//                        probe's light that the measured one lacked
//   lower_bound_fraction the unrecovered regions' lower bounds / (measured + lower bounds): the
//                        share of the probe's light that is only a lower bound (they are in it)
//   residuals[]          per ball: relative RMS of captured vs computed from the probe, before and
//                        after (lights/source_recovery.h BallResidual), per view too
#pragma once

#include "calib/probe/probe.h"
#include "lights/source_recovery.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

namespace rsibr {

struct RecoveredProbe {
  Probe measured;  // the chrome maps' blend (calib/probe/probe.h)
  EnvMap env;      // the probe with the sources added, and the lower bounds where none was recovered
  cv::Mat flags;   // CV_8UC1: kProbeLowerBound, kProbeSource (calib/probe/probe.h)
  std::vector<ClippedRegion> regions;
  SourceRecovery recovery;
  nlohmann::json summary;
};

// The chrome ball's Fresnel from a spec (bake/brdf_spec.h), or none for "" and "none" (the probe
// then holds F L). Throws std::invalid_argument("<option>: <problem>").
std::shared_ptr<const Fresnel> chrome_fresnel_from_spec(const std::string& spec, const std::string& option);

// The chrome maps are blended (assemble_probe with `probe`), and once more without each view for
// the jackknife's folds (lights/source_recovery.h). `recover` false: the regions are found and
// summarised, no source is added. A region with no source keeps its lower bound (Probe::lower_bound)
// in `env`, flagged kProbeLowerBound.
RecoveredProbe recover_probe_sources(const MapSet& chrome, const ProbeOptions& probe,
                                     const std::vector<GreyBallMaps>& grey, const std::vector<GlossyBallMaps>& glossy,
                                     const SourceRecoveryOptions& options, bool recover = true);

// Directions no view saw (neither trusted nor clipped) filled from the trusted ones
// (calib/probe/probe_fill.h) and flagged kProbeFilled, so a renderer can use the probe. Returns the filled
// solid-angle fraction.
double fill_unseen_directions(RecoveredProbe& probe, double min_weight);

// Writes `env` with its `confidence` (the trusted texels' summed weight, 0 elsewhere) and `flags`
// channels (calib/probe/probe.h, write_probe). Throws FileError(path, problem).
void write_recovered_probe(const std::string& path, const RecoveredProbe& probe, double min_weight);

// One line for a terminal or a report: "2 clipped light sources; recovered 61% / 59% / 47% (R/G/B)
// of the probe's light from grey", or "" when nothing was clipped.
std::string light_sources_line(const nlohmann::json& summary);

}  // namespace rsibr
