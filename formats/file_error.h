// An error about one of the user's files, with its parts kept as data: the file, whether it was
// being read (an input) or written (an output), where in it (a part, a view, a key; may be
// empty), the pipeline step that met it (may be empty) and what is wrong. Callers that add context
// build a new FileError from the parts instead of parsing or prefixing what() strings.
//
//   what() = "[<step>: ]<file>: [<where>: ]<problem>"
//
// The command line turns an input's FileError into exit status 2 (the inputs are refused) and an
// output's into 1 (the work failed), whatever verb met it.
#pragma once

#include <stdexcept>
#include <string>

namespace rsibr {

enum class FileRole { Input, Output };

class FileError : public std::runtime_error {
 public:
  FileError(std::string file, std::string problem, std::string where = {}, FileRole role = FileRole::Input,
            std::string step = {})
      : std::runtime_error(compose(step, file, where, problem)),
        file_(std::move(file)),
        where_(std::move(where)),
        problem_(std::move(problem)),
        step_(std::move(step)),
        role_(role) {}

  const std::string& file() const noexcept { return file_; }
  const std::string& where() const noexcept { return where_; }
  const std::string& problem() const noexcept { return problem_; }
  const std::string& step() const noexcept { return step_; }
  FileRole role() const noexcept { return role_; }

  // The same error located further in: `outer` goes before the current where ("part 3", "view02").
  FileError within(const std::string& outer) const {
    return FileError(file_, problem_, where_.empty() ? outer : outer + ": " + where_, role_, step_);
  }
  // The same error, met by a pipeline step.
  FileError in_step(const std::string& step) const { return FileError(file_, problem_, where_, role_, step); }

 private:
  static std::string compose(const std::string& step, const std::string& file, const std::string& where,
                             const std::string& problem) {
    return (step.empty() ? "" : step + ": ") + file + ": " + (where.empty() ? "" : where + ": ") + problem;
  }
  std::string file_, where_, problem_, step_;
  FileRole role_;
};

// Runs f(); any exception that is not already a FileError becomes FileError(file, what(), role)
// (with line breaks folded: errors are one line). For wrapping a reader or writer whose libraries
// throw plain exceptions (OpenEXR's do not derive from std::runtime_error).
template <typename F>
auto with_file(const std::string& file, F&& f, FileRole role = FileRole::Input) -> decltype(f()) {
  try {
    return f();
  } catch (const FileError&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    for (char& c : what)
      if (c == '\n' || c == '\r') c = ' ';
    throw FileError(file, what, {}, role);
  }
}

}  // namespace rsibr
