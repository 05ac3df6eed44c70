// All the files a verb writes, checked together before any work starts and put in place together
// after it succeeds, so that a bad output path never costs the work, an output never replaces an
// input, and a failure leaves nothing behind:
//
//   OutputPlan out({a.env, a.brdf});              // every file the verb reads
//   const std::string exr = out.file(a.output);   // checked now; the temporary to write
//   const std::string json = out.file(a.json);    // "" (none) and "-" (stdout) pass through
//   ... the work, writing exr and json ...
//   out.commit();                                 // every temporary renamed onto its target
//
// A file output is refused (std::invalid_argument("<path>: <problem>")) when its folder does not
// exist or is not writable, when it names a folder, a FIFO, a device or another non-regular file,
// or when it is one of the inputs or another output (by file identity: hard links, symlinks and
// different spellings of one path are the same file). Temporaries sit next to their targets
// (same folder, so the rename is atomic; same extension, for writers that pick the format by it)
// and are removed when the plan is destroyed without a commit.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace rsibr {

class OutputPlan {
 public:
  explicit OutputPlan(std::vector<std::filesystem::path> inputs = {});
  ~OutputPlan();
  OutputPlan(const OutputPlan&) = delete;
  OutputPlan& operator=(const OutputPlan&) = delete;

  // Checks `path` as a file output and returns the temporary to write in its place; "" and "-"
  // are returned as they are (no file, standard output).
  std::string file(const std::string& path);

  // Checks `path` as an output folder (its parent exists and is writable; it is not an existing
  // file, an input or another output). The folder is written by its own all-or-nothing writer
  // (formats/atomic_folder.h); the plan only keeps file outputs from colliding with it.
  void folder(const std::string& path);

  // Renames every temporary onto its target, in the order the files were added, after every one
  // has passed formats/written_file_check.h (std::runtime_error naming the target; nothing renamed).
  // A temporary that was never written is a std::logic_error (a verb that registers an output
  // must write it).
  void commit();

  // `message` with every temporary this process's plans handed out replaced by its target: an
  // error raised while writing a temporary names the file the user asked for.
  static std::string naming_targets(std::string message);

 private:
  void check_distinct(const std::filesystem::path& path, const std::string& kind);
  std::vector<std::filesystem::path> inputs_;
  std::vector<std::filesystem::path> outputs_;  // absolute, normal, for the identity checks
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // (temporary, target)
  bool committed_ = false;
};

}  // namespace rsibr
