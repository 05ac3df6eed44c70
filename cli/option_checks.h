// Checks of option values shared by several verbs, applied when the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace rsibr::cli {

// --seed: a whole number from 0 to 2^64 - 1 (CLI11 alone wraps larger numbers around, so
// 18446744073709551616 would silently become another seed).
inline CLI::Validator seed_check() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        static const std::string max = "18446744073709551615";
        if (s.empty() || s.size() > max.size() || s.find_first_not_of("0123456789") != std::string::npos ||
            (s.size() == max.size() && s > max))
          return "expected a whole number from 0 to " + max + ", got '" + s + "'";
        return "";
      },
      "UINT64");
}

}  // namespace rsibr::cli
