// The report's account of clipped light (pipeline/html_report.h, the sources step's summary,
// lights/recovered_probe.h): which regions of the probe were clipped in every chrome view, what was
// recovered from which ball with its sigma, how much of the light that is, the balls' agreement
// with the probe before and after, and the probe around each source before and after.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace rsibr {

// The HTML section ("" when the summary lists no clipped region). `dir` holds probe-measured.exr
// and probe.exr (their crops around each source are pictured when both exist).
std::string light_sources_section(const std::filesystem::path& dir, const nlohmann::json& summary);

// The warning of the comparison ("" when nothing was clipped): each clipped source by direction
// and the fraction of the light it holds (recovered, with the balls it came from), or the least
// fraction missing when it was not recovered.
std::string light_sources_warning(const nlohmann::json& summary);

}  // namespace rsibr
