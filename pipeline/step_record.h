// Resumable steps (rsibr process): each step of the pipeline records, in DIR/steps/<step>.json, the
// files it read and wrote (each: path, size, modification time and SHA-256 of the contents) and the
// settings it ran with (JSON). Paths are stored relative to a root when they lie under one: the run
// folder DIR ("root": "run") or the photo folder ("root": "photos"), else absolute; so a run
// folder copied or moved elsewhere (and a photo folder moved) still resolves its records.
//
// Each record holds rsibr's version and the code's (pipeline/code_version.h). A step is up to date,
// and skipped, when its record exists and was made by this code, its settings are equal, its inputs
// are the same files (the same names under the same roots) and every input and output still has
// the recorded contents: the same size and either the same mtime or, when the mtime differs (a
// copy that did not keep times), the same SHA-256. Anything else (a missing record, changed
// settings, an edited input, a deleted or replaced output) re-runs it; so does --force <step>.
// Records are written atomically, after the outputs.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct StepRecord {
  std::string step;
  nlohmann::json settings = nlohmann::json::object();
  std::vector<std::filesystem::path> inputs, outputs;  // absolute (resolved against the roots when read)
  double seconds = 0;                                  // how long the step took when it ran
  nlohmann::json summary = nlohmann::json::object();   // what the step reports (for the report)
};

// The folders that paths in records are relative to: the run folder and (optional) the photo folder.
struct RecordRoots {
  std::filesystem::path run, photos;
};

// What a file looks like: {"path", "root" (when relative), "size", "mtime_ns", "sha256"}.
// Throws std::runtime_error("<path>: ...") when it does not exist or cannot be read.
nlohmann::json file_stamp(const std::filesystem::path& file, const RecordRoots& roots = {});

// The SHA-256 of a file's contents, lower-case hex. Throws std::runtime_error("<path>: ...").
std::string file_sha256(const std::filesystem::path& file);

// The path a stamp names, resolved against the roots.
std::filesystem::path stamp_path(const nlohmann::json& stamp, const RecordRoots& roots);

std::filesystem::path step_record_path(const std::filesystem::path& dir, const std::string& step);

// Why the step must run ("" when it is up to date): "no record", "made by other code (rsibr V)",
// "settings changed", "inputs
// changed", "<input> changed", "<input> missing", "<output> missing", "<output> changed".
// roots.run is the run folder DIR (empty: `dir`).
std::string step_stale_reason(const std::filesystem::path& dir, const std::string& step, const nlohmann::json& settings,
                              const std::vector<std::filesystem::path>& inputs, const RecordRoots& roots = {});

// Writes DIR/steps/<step>.json (stamps of inputs and outputs taken now).
void write_step_record(const std::filesystem::path& dir, const StepRecord& record, const RecordRoots& roots = {});

// Reads a record; throws std::runtime_error("<file>: ...") when missing or malformed.
// A step that stopped: DIR/steps/STEP.failed.json with the step, the one-line error, the settings
// and what the step had found (its summary so far), so a failed run can be read. It is never
// taken for the step's record; remove_failed_step_record removes it once the step succeeds.
std::filesystem::path failed_step_record_path(const std::filesystem::path& dir, const std::string& step);
void write_failed_step_record(const std::filesystem::path& dir, const StepRecord& record, const std::string& error);
void remove_failed_step_record(const std::filesystem::path& dir, const std::string& step);

StepRecord read_step_record(const std::filesystem::path& dir, const std::string& step, const RecordRoots& roots = {});

}  // namespace rsibr
