#include "cli/bake_planning.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rsibr::cli {
namespace {

std::optional<double> budget_of(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const bool percent = text.back() == '%';
  const std::string number = percent ? text.substr(0, text.size() - 1) : text;
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(number, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != number.size() || !std::isfinite(v)) return std::nullopt;
  if (percent) v /= 100.0;
  if (!(v > 0 && v < 1)) return std::nullopt;
  return v;
}

std::string pct(double e) {
  std::ostringstream s;
  s << std::setprecision(e < 0.1 ? 2 : 3) << 100.0 * e << "%";
  return s.str();
}

}  // namespace

CLI::Validator error_budget_check() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        return budget_of(s) ? "" : "expected a relative error in (0, 1) such as 0.02 or 2%, got '" + s + "'";
      },
      "ERROR");
}

double parse_error_budget(const std::string& text) {
  const auto v = budget_of(text);
  if (!v)
    throw std::invalid_argument("--max-error: expected a relative error in (0, 1) such as 0.02 or 2%, got '" + text +
                                "'");
  return *v;
}

BakePlanOptions bake_plan_options(double max_error, const BakeKnobs& k, std::uint64_t seed) {
  BakePlanOptions o;
  o.max_error = max_error;
  o.seed = seed;
  o.normalise_albedo = k.normalise_albedo;
  if (k.views) o.view_sets = {*k.views};
  if (k.res) o.sizes = {*k.res};
  if (k.method) {
    std::vector<IntegratorSetting> kept;
    if (k.samples && (*k.method == "mis" || *k.method == "fis")) {
      kept.push_back({*k.method, *k.samples, 0});
    } else if (k.reference_width && *k.method == "reference") {
      kept.push_back({"reference", 0, *k.reference_width});
    } else {
      for (const IntegratorSetting& s : o.integrators)
        if (s.method == *k.method) kept.push_back(s);
    }
    o.integrators = kept;
  } else if (k.samples || k.reference_width) {
    throw std::invalid_argument(
        "--max-error: --samples and --reference-width fix a setting of one method; give --method too, or leave "
        "them to the plan");
  }
  if (o.integrators.empty()) throw std::invalid_argument("--max-error: no integrator setting is left to choose from");
  return o;
}

std::string bake_arguments(const BakeSetting& s) {
  std::ostringstream a;
  a << "--views " << s.views << " --res " << s.res << " --method " << s.integrator.method;
  if (s.integrator.method == "mis" || s.integrator.method == "fis") a << " --samples " << s.integrator.samples;
  if (s.integrator.method == "reference") a << " --reference-width " << s.integrator.reference_width;
  return a.str();
}

void print_plan(std::ostream& out, const BakePlan& plan) {
  const BakePlanOptions& o = plan.options;
  out << std::fixed;
  out << "pilot: " << o.pilot_views << " novel views x " << o.pilot_texels << " texels (" << o.pilot_size << "^2 discs"
      << (o.guide_size > 0 ? ", drawn where a " + std::to_string(o.guide_size) + "^2 bake is bright" : "")
      << "), truth: the full reference quadrature, " << std::setprecision(1) << plan.pilot_seconds << " s\n";
  if (o.confirm_views > 0)
    out << "confirmations: " << o.confirm_views << " further novel views x " << o.pilot_texels
        << " texels, drawn the same way; near the budget, fresh views up to "
        << std::max(o.confirm_views, o.confirm_max_views) << "\n";
  out << "integration error at the pilot texels (+- one standard error), and time per texel:\n";
  for (const IntegratorPilot& p : plan.integrators)
    out << "  " << std::left << std::setw(22) << p.setting.label() << std::right << std::setw(9) << pct(p.error)
        << " +- " << std::left << std::setw(8) << pct(p.error_sigma) << std::right << std::setw(9)
        << std::setprecision(2) << p.seconds_per_texel * 1e6 << " us\n";
  out << "interpolation error (warp and blend at novel views, maps without integration error";
  if (!plan.interpolation.empty())
    out << "; measured with " << plan.interpolation_integrator.label() << ", whose own error is "
        << pct(plan.interpolation_integrator_error);
  out << "):\n";
  for (const InterpolationPilot& p : plan.interpolation)
    out << "  " << std::setw(4) << p.view_count << " views " << std::setw(4) << p.res << "^2" << std::setw(9)
        << pct(p.error) << " +- " << pct(p.error_sigma) << "\n";
  out << "candidates by predicted time (predicted error = hypot(interpolation, integration); a candidate meets "
         "the budget when its error plus "
      << std::setprecision(1) << o.sigmas << " standard errors is within " << std::setprecision(0) << 100 * o.margin
      << "% of it):\n";
  auto row = [&](const PlannedSetting& s, bool chosen) {
    out << (chosen ? "  * " : "    ") << std::setw(4) << s.setting.view_count << " views " << std::setw(4)
        << s.setting.res << "^2  " << std::left << std::setw(22) << s.setting.integrator.label() << std::right
        << std::setw(10) << (s.interpolation_error ? pct(s.error) : ">= " + pct(s.integration_error)) << std::setw(10)
        << (s.interpolation_error ? "<= " + pct(s.upper_error) : std::string()) << std::setw(10) << std::setprecision(2)
        << s.seconds << " s" << (s.meets ? "  meets" : "") << "\n";
  };
  const std::size_t first = 6;
  bool chosen_shown = false;
  for (std::size_t i = 0; i < plan.settings.size() && i < first; ++i) {
    const bool chosen = plan.chosen && plan.settings[i].meets && !chosen_shown;
    chosen_shown = chosen_shown || chosen;
    row(plan.settings[i], chosen);
  }
  if (plan.chosen && !chosen_shown) {
    out << "    ...\n";
    row(*plan.chosen, true);
  }
  out << plan.why;
  out << std::defaultfloat;
}

}  // namespace rsibr::cli
