// Machine-readable summaries: a verb's --json FILE ('-' for stdout) gets one JSON object.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace rsibr::cli {

// Writes atomically unless target is "-" (stdout). Empty target: nothing.
void write_summary(const std::string& target, const nlohmann::json& summary);

}  // namespace rsibr::cli
