#include "pipeline/step_record.h"

#include "core/atomic_file.h"

#include <fstream>
#include <limits>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

nlohmann::json file_stamp(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
  return {{"path", fs::absolute(file).lexically_normal().string()},
          {"size", static_cast<std::uint64_t>(size)},
          {"mtime_ns", static_cast<std::int64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                           mtime.time_since_epoch()).count())}};
}

fs::path step_record_path(const fs::path& dir, const std::string& step) { return dir / "steps" / (step + ".json"); }

StepRecord read_step_record(const fs::path& dir, const std::string& step) {
  const fs::path file = step_record_path(dir, step);
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": no record of the step (run it first)");
  nlohmann::json j;
  try {
    in >> j;
    StepRecord r;
    r.step = j.at("step").get<std::string>();
    r.settings = j.at("settings");
    for (const auto& s : j.at("inputs")) r.inputs.emplace_back(s.at("path").get<std::string>());
    for (const auto& s : j.at("outputs")) r.outputs.emplace_back(s.at("path").get<std::string>());
    r.seconds = j.at("seconds").get<double>();
    r.summary = j.at("summary");
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": malformed step record (" + e.what() + ")");
  }
}

std::string step_stale_reason(const fs::path& dir, const std::string& step, const nlohmann::json& settings,
                              const std::vector<fs::path>& inputs) {
  std::ifstream in(step_record_path(dir, step));
  if (!in) return "no record";
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception&) {
    return "unreadable record";
  }
  if (!j.contains("settings") || j["settings"] != settings) return "settings changed";
  if (!j.contains("inputs") || !j.contains("outputs")) return "incomplete record";
  // The recorded inputs must be the ones asked for now, unchanged.
  std::vector<nlohmann::json> now;
  for (const fs::path& p : inputs) {
    std::error_code ec;
    if (!fs::exists(p, ec)) return p.string() + " missing";
    now.push_back(file_stamp(p));
  }
  if (j["inputs"].size() != now.size()) return "inputs changed";
  std::int64_t newest_input = std::numeric_limits<std::int64_t>::min();  // file_clock times can be negative
  for (std::size_t i = 0; i < now.size(); ++i) {
    if (j["inputs"][i] != now[i]) return now[i]["path"].get<std::string>() + " changed";
    newest_input = std::max(newest_input, now[i]["mtime_ns"].get<std::int64_t>());
  }
  for (const auto& o : j["outputs"]) {
    const fs::path p = o.at("path").get<std::string>();
    std::error_code ec;
    if (!fs::exists(p, ec)) return p.string() + " missing";
    const nlohmann::json s = file_stamp(p);
    if (s["mtime_ns"].get<std::int64_t>() < newest_input) return p.string() + " older than its inputs";
    if (s != o) return p.string() + " changed";
  }
  return "";
}

void write_step_record(const fs::path& dir, const StepRecord& r) {
  nlohmann::json j;
  j["rsibr_step"] = 1;
  j["step"] = r.step;
  j["settings"] = r.settings;
  j["inputs"] = nlohmann::json::array();
  for (const fs::path& p : r.inputs) j["inputs"].push_back(file_stamp(p));
  j["outputs"] = nlohmann::json::array();
  for (const fs::path& p : r.outputs) j["outputs"].push_back(file_stamp(p));
  j["seconds"] = r.seconds;
  j["summary"] = r.summary;
  fs::create_directories(dir / "steps");
  // Input text (names, the camera) is not always UTF-8: bad bytes are replaced.
  write_text_atomically(step_record_path(dir, r.step), j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace rsibr
