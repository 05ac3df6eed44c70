#include "formats/output_plan.h"

#include "formats/file_error.h"
#include "formats/written_file_check.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <mutex>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

// Every temporary handed out in this process, with its target (a handful per run): errors are
// reported after the plan that made them is gone.
std::vector<std::pair<std::string, std::string>>& temporaries() {
  static std::vector<std::pair<std::string, std::string>> names;
  return names;
}
std::mutex& temporaries_mutex() {
  static std::mutex m;
  return m;
}
void remember_temporary(const std::string& tmp, const std::string& target) {
  const std::lock_guard<std::mutex> lock(temporaries_mutex());
  temporaries().emplace_back(tmp, target);
}

// The path with symlinks resolved as far as it exists ("out/./a.json" and "out/a.json" are one).
fs::path identity(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec).lexically_normal();
  if (abs.filename().empty() && abs.has_parent_path()) abs = abs.parent_path();
  const fs::path real = fs::weakly_canonical(abs, ec);
  return ec ? abs : real;
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return identity(a) == identity(b);
}

void check_parent(const fs::path& path) {
  const fs::path abs = identity(path);
  const fs::path folder = abs.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw std::invalid_argument(path.string() + ": the folder " + folder.string() + " does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    throw std::invalid_argument(path.string() + ": the folder " + folder.string() + " is not writable");
}

}  // namespace

OutputPlan::OutputPlan(std::vector<fs::path> inputs) : inputs_(std::move(inputs)) {}

OutputPlan::~OutputPlan() {
  if (committed_) return;
  std::error_code ec;
  for (const auto& [tmp, target] : staged_) fs::remove(tmp, ec);
}

void OutputPlan::check_distinct(const fs::path& path, const std::string& kind) {
  for (const fs::path& in : inputs_)
    if (!in.empty() && same_file(in, path))
      throw std::invalid_argument(path.string() + ": output would overwrite the input" +
                                  (in.string() == path.string() ? "" : " " + in.string()));
  for (const fs::path& out : outputs_)
    if (same_file(out, path)) throw std::invalid_argument(path.string() + ": named twice as an output (" + kind + ")");
  outputs_.push_back(identity(path));
}

std::string OutputPlan::file(const std::string& path) {
  if (path.empty() || path == "-") return path;
  const fs::path p(path);
  if (p.filename().empty() || p.filename() == "." || p.filename() == "..")
    throw std::invalid_argument(path + ": expected a file name, not a folder");
  check_parent(p);
  struct stat st {};
  if (::stat(p.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw std::invalid_argument(path + ": is a folder, expected a file");
    if (!S_ISREG(st.st_mode))
      throw std::invalid_argument(path +
                                  ": is not a regular file (a FIFO, a socket or a device); refused as an output");
  }
  check_distinct(p, "a file");
  static std::atomic<int> counter{0};
  fs::path tmp = p;
  tmp.replace_filename("." + p.stem().string() + ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                       p.extension().string());
  staged_.emplace_back(tmp, p);
  remember_temporary(tmp.string(), path);
  return tmp.string();
}

void OutputPlan::folder(const std::string& path) {
  if (path.empty()) throw std::invalid_argument("the output folder name is empty");
  const fs::path p(path);
  check_parent(p);
  std::error_code ec;
  if (fs::exists(p, ec) && !fs::is_directory(p, ec)) throw std::invalid_argument(path + ": exists and is not a folder");
  check_distinct(p, "a folder");
}

std::string OutputPlan::naming_targets(std::string message) {
  const std::lock_guard<std::mutex> lock(temporaries_mutex());
  for (const auto& [tmp, target] : temporaries())
    for (std::size_t at; (at = message.find(tmp)) != std::string::npos;) message.replace(at, tmp.size(), target);
  return message;
}

void OutputPlan::commit() {
  std::error_code ec;
  for (const auto& [tmp, target] : staged_)
    if (!fs::exists(tmp, ec)) throw std::logic_error(target.string() + ": the output was never written");
  for (const auto& [tmp, target] : staged_) check_written_file(tmp, target);
  for (const auto& [tmp, target] : staged_) {
    fs::rename(tmp, target, ec);
    if (ec) throw FileError(target.string(), "cannot put the output in place: " + ec.message(), {}, FileRole::Output);
  }
  committed_ = true;
}

}  // namespace rsibr
