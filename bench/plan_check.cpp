// The planner against a full sweep (plan/bake_plan.h): for one environment and BRDF, the plan for a
// budget, the chosen setting baked and checked at fresh novel views, and the sweep: every candidate
// ranked by its time from the measured cost per texel, and its error measured for real (its own
// integrator, blended at the same fresh texels, against the full reference) in that order until one
// meets the budget, the sweep's cheapest, which is then baked and timed too. bench/plan_check.py runs it over held-out
// environments and BRDFs and writes the docs/tradeoffs.md section "Planning for an error budget".
// Output: one JSON object on stdout.
//
// The sweep does not depend on the planner (the same check texels, seeds and candidates), and it is
// most of the run: --sweep-only writes it alone, and --sweep-from reads one back (its environment,
// BRDF, budget, seeds and check size must match), re-timing only the sweep's best bake, so that a
// planner change is checked at the cost of the plan, the truth and two bakes.
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "formats/exr_io.h"
#include "core/stopwatch.h"
#include "core/texel_audit.h"
#include "plan/bake_plan.h"
#include "plan/error_sample.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

using namespace rsibr;

namespace {

// The integrator's options as the plan measured them (its seed: a FIS bake's error depends on it).
IntegratorOptions options_of(const IntegratorSetting& s, std::uint64_t seed) {
  IntegratorOptions o;
  o.seed = seed;
  o.samples = std::max(1, s.samples);
  o.reference_width = s.reference_width;
  return o;
}

// Bakes the setting in full and returns the wall time (integrator construction included).
double bake_seconds(const EnvMap& env, const Brdf& brdf, const BakeSetting& s, std::uint64_t seed, MapSet* out) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto integrator = make_integrator(s.integrator.method, env);
  MapSetBakeOptions o;
  o.res = s.res;
  o.integrator = options_of(s.integrator, seed);
  *out = bake_map_set(brdf, *integrator, ViewSet::named(s.views), o);
  return seconds_since(t0);
}

nlohmann::json setting_json(const BakeSetting& s) {
  return {{"views", s.view_count}, {"res", s.res}, {"integrator", s.integrator.label()}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string env_path, brdf_spec;
  double budget = 0.02;
  int check_views = 64, check_texels = 96;
  double max_bake_seconds = 600;    // longer bakes are not run: their time is the model's
  double max_sweep_seconds = 1800;  // candidates whose modelled bake is longer are not measured
  bool skip_full_reference = true;
  bool sweep_only = false;
  std::string sweep_from;
  std::uint64_t check_seed = 7777, plan_seed = 1;
  CLI::App app("The bake planner against a full sweep of its candidates");
  app.add_option("--env", env_path)->required();
  app.add_option("--brdf", brdf_spec, "BRDF spec (YAML text)")->required();
  app.add_option("--max-error", budget);
  app.add_option("--check-views", check_views);
  app.add_option("--check-texels", check_texels);
  app.add_option("--max-bake-seconds", max_bake_seconds);
  app.add_option("--max-sweep-seconds", max_sweep_seconds);
  app.add_option("--check-seed", check_seed);
  app.add_option("--plan-seed", plan_seed);
  app.add_flag("--sweep-only", sweep_only, "run the sweep alone (no plan, no bakes)");
  app.add_option("--sweep-from", sweep_from, "a --sweep-only output to reuse instead of sweeping");
  CLI11_PARSE(app, argc, argv);
  try {
    EnvMap env = read_environment(env_path);
    sanitize_texels(env.pixels);  // lossy-compression ringing: negatives to 0
    const auto brdf = parse_brdf(brdf_spec);
    nlohmann::json out;
    out["env"] = env_path;
    out["brdf"] = brdf->spec();
    out["max_error"] = budget;
    out["check_seed"] = check_seed;
    out["plan_seed"] = plan_seed;

    // The plan and its bake, checked at fresh novel views.
    BakePlanOptions po;
    po.max_error = budget;
    po.seed = plan_seed;
    auto t0 = std::chrono::steady_clock::now();
    BakePlan plan;
    if (!sweep_only) {
      plan = plan_bake(env, *brdf, po);
      out["plan"] = plan.to_json();
      out["plan_seconds"] = seconds_since(t0);
    }
    // The check's texels: guided like the pilot's (plan/error_sample.h), from another seed.
    const auto guide_integrator = make_integrator("fis", env);
    IntegratorOptions guide_options;
    guide_options.samples = 64;
    guide_options.seed = check_seed;
    const ErrorSample sample(check_views, check_texels, 128, check_seed,
                             squared_radiance_guide(*guide_integrator, *brdf, guide_options, 32));
    const auto reference = make_integrator("reference", env);
    t0 = std::chrono::steady_clock::now();
    const std::vector<Vec3> truth = direct_values(*reference, *brdf, IntegratorOptions{}, sample);
    out["truth_seconds"] = seconds_since(t0);
    out["check_views"] = check_views;
    out["check_texels"] = check_texels;
    if (!sweep_only && plan.chosen) {
      const BakeSetting& cs = plan.chosen->setting;
      out["chosen"] = setting_json(cs);
      out["chosen"]["predicted_error"] = plan.chosen->error;
      out["chosen"]["pilot_error"] = *plan.chosen->measured_error;
      out["chosen"]["pilot_sigma"] = *plan.chosen->measured_sigma;
      out["chosen"]["predicted_seconds"] = plan.chosen->seconds;
      if (plan.chosen->seconds <= max_bake_seconds) {
        MapSet set;
        out["chosen"]["seconds"] = bake_seconds(env, *brdf, cs, plan_seed, &set);
        const SampledBlend b = sampled_blend(set, ViewSet::named(cs.views), sample);
        const ErrorEstimate e = sample_error(sample, b.values, truth, &b.weights);
        out["chosen"]["error"] = e.value;
        out["chosen"]["error_sigma"] = e.sigma;
      } else {  // too long to bake here: the same texels through the footprints, the time as predicted
        const auto in = make_integrator(cs.integrator.method, env);
        const SampledBlend b = sampled_blend(*in, *brdf, options_of(cs.integrator, plan_seed), ViewSet::named(cs.views),
                                             cs.res, false, sample);
        const ErrorEstimate e = sample_error(sample, b.values, truth, &b.weights);
        out["chosen"]["error"] = e.value;
        out["chosen"]["error_sigma"] = e.sigma;
        out["chosen"]["seconds"] = plan.chosen->seconds;
        out["chosen"]["seconds_modelled"] = true;
      }
    }

    std::optional<nlohmann::json> best;
    BakeSetting best_setting;
    if (!sweep_from.empty()) {
      std::ifstream f(sweep_from);
      if (!f) throw std::runtime_error(sweep_from + ": cannot open");
      const nlohmann::json kept = nlohmann::json::parse(f);
      for (const char* key : {"env", "brdf", "max_error", "check_seed", "plan_seed", "check_views", "check_texels"})
        if (!kept.contains(key) || kept[key] != out[key]) {
          // The environment by its file name: a kept sweep travels with the repository.
          const bool same_env = std::string(key) == "env" && kept[key].is_string() &&
                                std::filesystem::path(kept[key].get<std::string>()).filename() ==
                                    std::filesystem::path(env_path).filename();
          if (!same_env) throw std::runtime_error(sweep_from + ": its " + key + " differs from this run's");
        }
      for (const char* key : {"candidates", "max_sweep_seconds", "sweep", "pruned", "own_errors", "sweep_seconds"})
        out[key] = kept.at(key);
      if (kept.contains("sweep_best")) {
        best = kept["sweep_best"];
        const nlohmann::json& b = *best;
        const std::string label = b["integrator"];
        for (const IntegratorSetting& s : po.integrators)
          if (s.label() == label) best_setting.integrator = s;
        if (best_setting.integrator.method.empty()) throw std::runtime_error(sweep_from + ": unknown " + label);
        for (const std::string& views : po.view_sets)
          if (int(ViewSet::named(views).views().size()) == b["views"].get<int>()) best_setting.views = views;
        if (best_setting.views.empty())
          throw std::runtime_error(sweep_from + ": no candidate view set has " + b["views"].dump() + " views");
        best_setting.view_count = b["views"];
        best_setting.res = b["res"];
      }
      out["sweep_from"] = sweep_from;
    } else {
      // The sweep: every candidate's real error at the check texels; its time from the cost per
      // texel measured here (a whole 128^2 map per integrator setting).
      const auto sweep_start = std::chrono::steady_clock::now();
      std::map<std::string, std::unique_ptr<Integrator>> made;
      std::map<std::string, double> setup;
      auto integrator = [&](const std::string& m) -> const Integrator& {
        if (!made.count(m)) {
          const auto t = std::chrono::steady_clock::now();
          made[m] = make_integrator(m, env);
          setup[m] = seconds_since(t);
        }
        return *made[m];
      };
      std::map<std::string, double> per_texel;
      std::vector<IntegratorSetting> settings;
      nlohmann::json pruned = nlohmann::json::array();
      nlohmann::json own_errors;  // each integrator setting's own error at the check texels
      for (const IntegratorSetting& s : po.integrators) {
        if (skip_full_reference && s.method == "reference" && s.reference_width == 0) continue;
        try {
          const Integrator& in = integrator(s.method);
          // A setting whose own error at the check texels exceeds the budget cannot meet it blended
          // (blending adds interpolation error): pruned from the sweep.
          const double own =
              sample_error(sample, direct_values(in, *brdf, options_of(s, plan_seed), sample), truth).value;
          own_errors[s.label()] = own;
          if (own > budget) {
            pruned.push_back({{"integrator", s.label()}, {"error", own}});
            continue;
          }
          const auto t = std::chrono::steady_clock::now();
          in.radiance_map(*brdf, sample.view(0), sample.frame(0), 128, options_of(s, plan_seed));
          per_texel[s.label()] = seconds_since(t) / double(disc_texel_count(128));
          settings.push_back(s);
        } catch (const std::invalid_argument&) {
        }
      }
      // Every candidate by modelled time; errors measured in that order until one meets the budget:
      // that one is the sweep's cheapest (every candidate after it takes longer), so the candidates
      // after it need no measurement.
      struct Row {
        BakeSetting setting;
        double model;
      };
      std::vector<Row> all;
      for (const std::string& views : po.view_sets) {
        const int count = int(ViewSet::named(views).views().size());
        for (int res : po.sizes)
          for (const IntegratorSetting& s : settings)
            all.push_back({{views, count, res, s},
                           setup[s.method] + double(count) * double(disc_texel_count(res)) * per_texel[s.label()]});
      }
      std::stable_sort(all.begin(), all.end(), [](const Row& a, const Row& b) { return a.model < b.model; });
      // A candidate is measured a few check views at a time and left as soon as it provably misses
      // (plan/error_sample.h, sampled_blend_error); one that meets the budget is measured at every view.
      BlendErrorOptions stop;
      stop.stop_above = budget;
      stop.step = std::max(1, sample.view_count() / 8);
      nlohmann::json rows = nlohmann::json::array();
      for (const Row& row : all) {
        if (row.model > max_sweep_seconds) break;  // bakes over this long are not candidates here
        const auto t = std::chrono::steady_clock::now();
        const BakeSetting& bs = row.setting;
        const BlendErrorMeasure m =
            sampled_blend_error(integrator(bs.integrator.method), *brdf, options_of(bs.integrator, plan_seed),
                                ViewSet::named(bs.views), bs.res, false, sample, truth, stop);
        nlohmann::json r = setting_json(bs);
        r["seconds_model"] = row.model;
        if (!m.error) {  // provably over the budget: a lower bound
          r["error_at_least"] = m.at_least;
          r["views_measured"] = m.views;
          r["sweep_seconds"] = seconds_since(t);
          rows.push_back(r);
          continue;
        }
        const ErrorEstimate e = *m.error;
        const double error = e.value;
        r["error"] = error;
        r["error_sigma"] = e.sigma;
        r["sweep_seconds"] = seconds_since(t);
        rows.push_back(r);
        if (error <= budget) {
          best = r;
          best_setting = bs;
          break;
        }
      }
      out["candidates"] = all.size();
      out["max_sweep_seconds"] = max_sweep_seconds;
      out["sweep"] = rows;
      out["pruned"] = pruned;
      out["own_errors"] = own_errors;
      out["sweep_seconds"] = seconds_since(sweep_start);
    }
    if (best && sweep_only) {
      out["sweep_best"] = *best;
    } else if (best) {
      if ((*best)["seconds_model"].get<double>() <= max_bake_seconds) {
        MapSet set;
        (*best)["seconds"] = bake_seconds(env, *brdf, best_setting, plan_seed, &set);
      } else {
        (*best)["seconds"] = (*best)["seconds_model"];
        (*best)["seconds_modelled"] = true;
      }
      out["sweep_best"] = *best;
    }
    std::cout << out.dump(1) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rsibr_plan_check: " << e.what() << "\n";
    return 1;
  }
}
