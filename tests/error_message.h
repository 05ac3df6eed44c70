#pragma once
// The message of the refusal a call throws (std::invalid_argument, or a FileError: a missing or
// unreadable input), or "" when it throws none: tests of refusals compare against the one line a
// user would read.
#include "formats/file_error.h"

#include <functional>
#include <stdexcept>
#include <string>

namespace rsibr::test_support {

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace rsibr::test_support
