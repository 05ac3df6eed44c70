// Resumable steps (rsibr process): each step of the pipeline records, in DIR/steps/<step>.json, the
// files it read (path, size, modification time), the settings it ran with (JSON) and the files it
// wrote. A step is up to date, and skipped, when its record exists, its settings are equal, every
// input still has the recorded size and mtime, and every output exists and is not older than any
// input. Anything else (a missing record, changed settings, a touched input, a deleted output)
// re-runs it; so does --force <step>. Records are written atomically, after the outputs.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct StepRecord {
  std::string step;
  nlohmann::json settings = nlohmann::json::object();
  std::vector<std::filesystem::path> inputs, outputs;
  double seconds = 0;                                    // how long the step took when it ran
  nlohmann::json summary = nlohmann::json::object();     // what the step reports (for the report)
};

// What a file looked like: {"path", "size", "mtime_ns"}. Throws std::runtime_error("<path>: ...")
// when it does not exist.
nlohmann::json file_stamp(const std::filesystem::path& file);

std::filesystem::path step_record_path(const std::filesystem::path& dir, const std::string& step);

// Why the step must run ("" when it is up to date): "no record", "settings changed", "<input>
// changed", "<output> missing", "<output> older than <input>".
std::string step_stale_reason(const std::filesystem::path& dir, const std::string& step,
                              const nlohmann::json& settings, const std::vector<std::filesystem::path>& inputs);

// Writes DIR/steps/<step>.json (stamps of inputs and outputs taken now).
void write_step_record(const std::filesystem::path& dir, const StepRecord& record);

// Reads a record; throws std::runtime_error("<file>: ...") when missing or malformed.
StepRecord read_step_record(const std::filesystem::path& dir, const std::string& step);

}  // namespace rsibr
