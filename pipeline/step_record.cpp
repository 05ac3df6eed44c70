#include "pipeline/step_record.h"

#include "pipeline/code_version.h"

#include "formats/atomic_file.h"

#include <openssl/evp.h>

#include <fstream>
#include <memory>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

fs::path normal(const fs::path& p) { return fs::absolute(p).lexically_normal(); }

// p relative to root when it lies under it ("" otherwise).
fs::path under(const fs::path& p, const fs::path& root) {
  if (root.empty()) return {};
  const fs::path rel = p.lexically_relative(normal(root));
  if (rel.empty() || *rel.begin() == "..") return {};
  return rel;
}

// {"path", "root"}: relative to the more specific root that holds the file, else absolute.
nlohmann::json located(const fs::path& file, const RecordRoots& roots) {
  const fs::path p = normal(file);
  const fs::path a = under(p, roots.run), b = under(p, roots.photos);
  nlohmann::json j;
  if (!a.empty() && (b.empty() || std::distance(a.begin(), a.end()) <= std::distance(b.begin(), b.end()))) {
    j["path"] = a.generic_string();
    j["root"] = "run";
  } else if (!b.empty()) {
    j["path"] = b.generic_string();
    j["root"] = "photos";
  } else {
    j["path"] = p.string();
  }
  return j;
}

bool same_place(const nlohmann::json& recorded, const nlohmann::json& now) {
  return recorded.value("path", "") == now.value("path", "") && recorded.value("root", "") == now.value("root", "");
}

// The file still has the recorded contents: its size and its mtime or (when the mtime differs) its SHA-256.
bool same_contents(const nlohmann::json& recorded, const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec || !recorded.contains("size") || recorded["size"].get<std::uint64_t>() != size) return false;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return false;
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch()).count();
  if (recorded.contains("mtime_ns") && recorded["mtime_ns"].get<std::int64_t>() == static_cast<std::int64_t>(ns))
    return true;
  return recorded.contains("sha256") && recorded["sha256"].get<std::string>() == file_sha256(file);
}

}  // namespace

std::string file_sha256(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read");
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error(file.string() + ": SHA-256 unavailable");
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx.get(), buf.data(), std::size_t(in.gcount()));
  }
  if (in.bad()) throw std::runtime_error(file.string() + ": read error");
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestFinal_ex(ctx.get(), md, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) out += hex[md[i] >> 4], out += hex[md[i] & 15];
  return out;
}

nlohmann::json file_stamp(const fs::path& file, const RecordRoots& roots) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
  nlohmann::json j = located(file, roots);
  j["size"] = static_cast<std::uint64_t>(size);
  j["mtime_ns"] =
      static_cast<std::int64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch()).count());
  j["sha256"] = file_sha256(file);
  return j;
}

fs::path stamp_path(const nlohmann::json& stamp, const RecordRoots& roots) {
  const fs::path p = stamp.at("path").get<std::string>();
  const std::string root = stamp.value("root", "");
  if (root == "run") return normal(roots.run / p);
  if (root == "photos") return normal(roots.photos / p);
  return p;
}

fs::path step_record_path(const fs::path& dir, const std::string& step) { return dir / "steps" / (step + ".json"); }

namespace {
RecordRoots with_run(const fs::path& dir, RecordRoots roots) {
  if (roots.run.empty()) roots.run = dir;
  return roots;
}
}  // namespace

StepRecord read_step_record(const fs::path& dir, const std::string& step, const RecordRoots& given) {
  const RecordRoots roots = with_run(dir, given);
  const fs::path file = step_record_path(dir, step);
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": no record of the step (run it first)");
  nlohmann::json j;
  try {
    in >> j;
    StepRecord r;
    r.step = j.at("step").get<std::string>();
    r.settings = j.at("settings");
    for (const auto& s : j.at("inputs")) r.inputs.push_back(stamp_path(s, roots));
    for (const auto& s : j.at("outputs")) r.outputs.push_back(stamp_path(s, roots));
    r.seconds = j.at("seconds").get<double>();
    r.summary = j.at("summary");
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": malformed step record (" + e.what() + ")");
  }
}

std::string step_stale_reason(const fs::path& dir, const std::string& step, const nlohmann::json& settings,
                              const std::vector<fs::path>& inputs, const RecordRoots& given) {
  const RecordRoots roots = with_run(dir, given);
  std::ifstream in(step_record_path(dir, step));
  if (!in) return "no record";
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception&) {
    return "unreadable record";
  }
  // Outputs made by other code (another rsibr, or this one's sources changed since) are redone,
  // never reused: the code's fix or change is what the user runs a newer build for.
  if (!j.contains("code") || !j["code"].is_string() || j["code"].get<std::string>() != rsibr_code_version())
    return "made by other code (rsibr " +
           (j.contains("rsibr_version") && j["rsibr_version"].is_string() ? j["rsibr_version"].get<std::string>()
                                                                          : std::string("unknown")) +
           ")";
  if (!j.contains("settings") || j["settings"] != settings) return "settings changed";
  if (!j.contains("inputs") || !j.contains("outputs") || !j["inputs"].is_array() || !j["outputs"].is_array())
    return "incomplete record";
  if (j["inputs"].size() != inputs.size()) return "inputs changed";
  try {
    // The recorded inputs must be the ones asked for now, with the recorded contents.
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      std::error_code ec;
      if (!fs::exists(inputs[i], ec)) return inputs[i].string() + " missing";
      const nlohmann::json& rec = j["inputs"][i];
      if (!same_place(rec, located(inputs[i], roots)) || !same_contents(rec, inputs[i]))
        return inputs[i].string() + " changed";
    }
    for (const auto& o : j["outputs"]) {
      const fs::path p = stamp_path(o, roots);
      std::error_code ec;
      if (!fs::exists(p, ec)) return p.string() + " missing";
      if (!same_contents(o, p)) return p.string() + " changed";
    }
  } catch (const std::exception&) {
    return "incomplete record";
  }
  return "";
}

void write_step_record(const fs::path& dir, const StepRecord& r, const RecordRoots& given) {
  const RecordRoots roots = with_run(dir, given);
  nlohmann::json j;
  j["rsibr_step"] = 3;
  j["rsibr_version"] = RSIBR_VERSION;
  j["code"] = rsibr_code_version();
  j["step"] = r.step;
  j["settings"] = r.settings;
  j["inputs"] = nlohmann::json::array();
  for (const fs::path& p : r.inputs) j["inputs"].push_back(file_stamp(p, roots));
  j["outputs"] = nlohmann::json::array();
  for (const fs::path& p : r.outputs) j["outputs"].push_back(file_stamp(p, roots));
  j["seconds"] = r.seconds;
  j["summary"] = r.summary;
  fs::create_directories(dir / "steps");
  // Input text (names, the camera) is not always UTF-8: bad bytes are replaced.
  write_text_atomically(step_record_path(dir, r.step),
                        j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

fs::path failed_step_record_path(const fs::path& dir, const std::string& step) {
  return dir / "steps" / (step + ".failed.json");
}

void write_failed_step_record(const fs::path& dir, const StepRecord& r, const std::string& error) {
  nlohmann::json j;
  j["step"] = r.step;
  j["rsibr_version"] = RSIBR_VERSION;
  j["code"] = rsibr_code_version();
  j["status"] = "failed";
  j["error"] = error;
  j["settings"] = r.settings;
  j["summary"] = r.summary;
  fs::create_directories(dir / "steps");
  write_text_atomically(failed_step_record_path(dir, r.step),
                        j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void remove_failed_step_record(const fs::path& dir, const std::string& step) {
  std::error_code ec;
  fs::remove(failed_step_record_path(dir, step), ec);
}

}  // namespace rsibr
