// Checks of option values shared by several verbs, applied when the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// A number that is finite: CLI11 reads "nan", "inf" and "1e999" as doubles, and its Range check
// lets NaN through (every comparison with NaN is false). Text that is not a number is left to
// CLI11's own conversion, which names the option.
inline CLI::Validator finite_number_check() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str()) return "";
        if (!std::isfinite(v)) return "expected a finite number, got '" + s + "'";
        return "";
      },
      "");
}

// A number from lo to hi, both written with %g in the message (CLI::Range writes every digit).
inline CLI::Validator number_from_to(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !(v >= lo && v <= hi)) {
          char text[96];
          std::snprintf(text, sizeof text, "expected a number from %g to %g, got '", lo, hi);
          return text + s + "'";
        }
        return "";
      },
      "");
}

// finite_number_check on every floating-point option of `app` and its verbs (those CLI11 types
// FLOAT), so no verb can forget it.
inline void require_finite_numbers(CLI::App& app) {
  for (CLI::Option* o : app.get_options())
    if (o->get_type_name().find("FLOAT") != std::string::npos) o->check(finite_number_check());
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) require_finite_numbers(*sub);
}

}  // namespace rsibr::cli
