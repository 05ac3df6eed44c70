// What a step of rsibr process made: the files it wrote (for its record, pipeline/step_record.h)
// and its summary (the record's, the report's and the caller's facts).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

namespace rsibr {

struct StepOutputs {
  std::vector<std::filesystem::path> files;
  nlohmann::json summary = nlohmann::json::object();
};

}  // namespace rsibr
