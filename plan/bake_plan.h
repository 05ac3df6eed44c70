// Planning a bake for an error budget: the cheapest view set, map size and integrator whose maps,
// blended to any view, stay within a relative RMS error of the direct bake there
// (plan/error_sample.h defines the error).
//
// The prediction. The error of a setting (N views, size r, integrator m) splits into two parts that
// come from different places and are taken as independent:
//
//   e(N, r, m)^2 = e_interp(N, r)^2 + e_int(m)^2
//
//   e_int(m): the integrator's own error, a texel against the full reference quadrature. A texel's
//     value does not depend on the map it is in, so e_int is measured once per integrator at the
//     pilot's sampled texels (random novel views, uniform over their discs) against the reference.
//   e_interp(N, r): the warp and blend's error with maps that carry no integration error: the
//     sampled blend of the N-view set at size r against the direct values, both with one fixed
//     deterministic integrator (filtered importance sampling, 64 samples, whose smooth bias is
//     common to both and cancels). Measured per (N, r) with only the blend's footprints baked.
//
// Integration noise is not reduced by the blend's averaging in the prediction (it is, a little, in
// fact), so predictions err high. A setting is taken when e <= margin * budget; margin < 1 leaves
// room for the pilot's own sampling error (a relative RMS from a few hundred texels).
//
// The time of a setting: setup(m) + N * disc_texels(r) * t(m), with setup(m) the integrator's
// construction (its precomputation from the environment) and t(m) its wall time per texel, both
// measured in the pilot on this machine with its threads.
//
// The choice: the settings sorted by predicted time; the first that meets the budget. The pilot
// measures e_interp lazily, only for the (N, r) pairs it reaches and that no measured pair with at
// least as many views and texels already rules out, unless asked for every pair.
#pragma once

#include "bake/brdf.h"
#include "core/env_map.h"
#include "core/map_set.h"
#include "core/view_set.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

// One integrator setting: a method of bake/integrator.h with its quality knob.
struct IntegratorSetting {
  std::string method;       // "reference", "mis", "fis" or "sh"
  int samples = 0;          // mis, fis
  int reference_width = 0;  // reference: the widest MIP level it integrates (0: the full environment)
  // E.g. "fis 128 samples", "reference width 64", "reference (full)", "sh order 2".
  std::string label() const;
};

// The integrator settings a plan considers by default: reference widths 32-256 and full, mis 16-1024
// samples, fis 8-512 samples, sh (Lambert only; left out for other BRDFs).
std::vector<IntegratorSetting> default_integrator_settings();

struct BakeSetting {
  std::string views;  // a ViewSet::named name ("icosa", "42", "162", "642", ...)
  int view_count = 0;
  int res = 0;
  IntegratorSetting integrator;
};

struct BakePlanOptions {
  double max_error = 0.02;  // relative RMS of blends at novel views against direct bakes there
  // Steps of about 2x in cost: view counts about 2x apart (the geodesic sets and Fibonacci sets
  // between them), sizes sqrt 2 apart, so the margin below costs at most about one step.
  std::vector<std::string> view_sets = {"icosa", "fib24", "42", "fib84", "162", "fib324", "642", "fib1284", "fib2562"};
  std::vector<int> sizes = {32, 45, 64, 90, 128, 181, 256};
  std::vector<IntegratorSetting> integrators = default_integrator_settings();
  bool normalise_albedo = false;  // plan albedo-normalised maps (core/albedo_normalisation.h)
  // The pilot: novel views, texels per view and the destination size they are drawn from.
  int pilot_views = 8;
  int pilot_texels = 96;
  int pilot_size = 128;
  std::uint64_t seed = 1;
  double margin = 0.8;      // a setting is taken when its predicted error <= margin * max_error
  bool every_pair = false;  // measure e_interp for every (views, size) pair, not only those reached
};

struct IntegratorPilot {
  IntegratorSetting setting;
  double error = 0;              // e_int: relative RMS against the full reference at the pilot texels
  double seconds_per_texel = 0;  // wall time
  double setup_seconds = 0;      // constructing the integrator from the environment
};

struct InterpolationPilot {
  std::string views;
  int view_count = 0;
  int res = 0;
  double error = 0;      // e_interp
  long long texels = 0;  // source texels baked to measure it
  double seconds = 0;
};

struct PlannedSetting {
  BakeSetting setting;
  double integration_error = 0;
  std::optional<double> interpolation_error;  // nullopt: not measured (not reached)
  double error = 0;                           // the prediction when interpolation_error is known, else e_int alone
  double seconds = 0;                         // predicted bake time
  bool meets = false;                         // predicted error <= margin * max_error (known only when measured)
};

struct BakePlan {
  BakePlanOptions options;
  std::vector<IntegratorPilot> integrators;
  std::vector<InterpolationPilot> interpolation;
  std::vector<PlannedSetting> settings;  // every candidate, by predicted time
  std::optional<PlannedSetting> chosen;  // nullopt: no candidate is predicted to meet the budget
  double pilot_seconds = 0;
  long long truth_texels = 0;  // reference texels of the pilot's truth
  std::string why;             // a few lines for people
  nlohmann::json to_json() const;
};

// The integrators alone, for maps that are not interpolated (baked at the frames they are used at,
// as `rsibr process` bakes the grey ball at the captured views): e_int and the time per texel of
// each setting at `sample`'s texels against the full reference, and the cheapest per texel with
// e_int <= margin * max_error (nullopt when none is).
struct IntegratorPlan {
  std::vector<IntegratorPilot> integrators;
  std::optional<IntegratorPilot> chosen;
  double max_error = 0, margin = 0.8, seconds = 0;
  nlohmann::json to_json() const;
};
IntegratorPlan plan_integrator(const EnvMap& env, const Brdf& brdf, double max_error,
                               const std::vector<IntegratorSetting>& settings = default_integrator_settings(),
                               std::uint64_t seed = 1, double margin = 0.8);

// Throws std::invalid_argument for a budget that is not in (0, 1), empty candidate lists, a view set
// or size that cannot be used, and what the integrators throw on construction.
BakePlan plan_bake(const EnvMap& env, const Brdf& brdf, const BakePlanOptions& options);

// The error of a baked set at fresh novel views (seed), measured as the plan predicts it: its blend
// against the full reference quadrature at `views` x `texels` sampled texels.
struct BakeCheck {
  double error = 0;
  int views = 0, texels = 0;
  double seconds = 0;
};
BakeCheck check_bake(const MapSet& set, const ViewSet& view_set, const EnvMap& env, const Brdf& brdf,
                     std::uint64_t seed, int views = 4, int texels = 96, int size = 128);

}  // namespace rsibr
