// What `rsibr plan` and `rsibr bake --max-error` share: the error budget's spelling, the plan's
// options from the knobs a user fixed, and the plan in words.
#pragma once

#include "plan/bake_plan.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

namespace rsibr::cli {

// --max-error: a relative RMS as a fraction ("0.02") or a percentage ("2%"), in (0, 1).
CLI::Validator error_budget_check();
double parse_error_budget(const std::string& text);  // after error_budget_check

// The knobs a user fixed on the command line (nullopt: the plan chooses).
struct BakeKnobs {
  std::optional<std::string> views;
  std::optional<int> res;
  std::optional<std::string> method;
  std::optional<int> samples;
  std::optional<int> reference_width;
  bool normalise_albedo = false;
};

// The default candidates, narrowed to the fixed knobs. Throws std::invalid_argument when a fixed
// combination leaves no integrator (e.g. --samples with --method reference).
BakePlanOptions bake_plan_options(double max_error, const BakeKnobs& knobs, std::uint64_t seed);

// The plan for people: the pilot's measurements, the cheapest candidates and why the choice.
void print_plan(std::ostream& out, const BakePlan& plan);

// The `rsibr bake` options that bake the chosen setting (after "rsibr bake --env E --brdf B").
std::string bake_arguments(const BakeSetting& s);

}  // namespace rsibr::cli
