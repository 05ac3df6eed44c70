// The report's account of the response model choice (hdr/response_recovery.h recovery_json): the
// chosen model, its margin from the other choice in standard errors of the held-out noise, the
// near-tie warning, the saturation codes and where they came from, and the candidates' held-out
// errors.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace rsibr {

// HTML (a paragraph and a table); empty for an empty object (a reused or given response).
std::string response_choice_html(const nlohmann::json& recovery);

}  // namespace rsibr
