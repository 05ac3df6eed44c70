#include "cli/summary.h"

#include "formats/atomic_file.h"

#include <fstream>
#include <iostream>
#include <stdexcept>

namespace rsibr::cli {

void write_summary(const std::string& target, const nlohmann::json& summary) {
  if (target.empty()) return;
  // Strings from input files may hold bytes that are not UTF-8: replaced (U+FFFD), never fatal.
  const std::string text = summary.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  if (target == "-") {
    std::cout << text;
    return;
  }
  write_text_atomically(target, text);
}

}  // namespace rsibr::cli
