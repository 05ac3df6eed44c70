#include "cli/summary.h"

#include "core/atomic_file.h"

#include <fstream>
#include <iostream>
#include <stdexcept>

namespace rsibr::cli {

void write_summary(const std::string& target, const nlohmann::json& summary) {
  if (target.empty()) return;
  const std::string text = summary.dump(2) + "\n";
  if (target == "-") {
    std::cout << text;
    return;
  }
  write_atomically(target, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error(target + ": cannot write the summary");
  });
}

}  // namespace rsibr::cli
