// Planning a bake for an error budget: the cheapest view set, map size and integrator whose maps,
// blended to any view, stay within a relative RMS error of the direct bake there
// (plan/error_sample.h defines the error).
//
// The model. The error of a setting (N views, size r, integrator m) has two parts that come from
// different places, modelled as independent:
//
//   e(N, r, m)^2 = e_interp(N, r)^2 + e_int(m)^2
//
//   e_int(m): the integrator's own error, a texel against the full reference quadrature. A texel's
//     value does not depend on the map it is in, so e_int is measured once per integrator at the
//     pilot's sampled texels (random novel views) against the reference.
//   e_interp(N, r): the warp and blend's error with maps that carry no integration error: the
//     sampled blend of the N-view set at size r against the direct values, both with one
//     deterministic integrator (filtered importance sampling: the cheapest of the pilot's FIS
//     settings whose own error is at most a third of the planned budget), less that integrator's
//     own error at the same texels in quadrature: its error at a destination texel is not the one
//     the blend carries from the sources' texels (it depends on the seed and the lobe), so it does
//     not cancel. Measured per (N, r) with only the blend's footprints baked.
//
// The pilot's texels are drawn guided by |D|^2 of a cheap 32^2 bake at each pilot view
// (plan/error_sample.h: a sun's glint, where most of the squared error sits, is sampled densely and
// weighted down), and each measured error carries its standard error (a jackknife over the pilot's
// views).
//
// The model screens, a measurement decides. The model is not trusted to choose: where a glint
// carries the error, interpolation and integration errors sit in the same texels and add more than
// in quadrature (up to e_interp + e_int), and a noisy integrator's error is partly averaged away by
// the blend, while e_interp measured with FIS maps carries FIS's own error pattern and overstates
// the blend's (up to 1.6x). So a candidate the model lets through (with mis errors counted at a
// third and e_interp at half until measurements say by how much to count them: the least factors
// the candidates measured so far imply) is measured: the set's blend at the confirmation texels (a
// sample of its own, confirm_views novel views, 4x the pilot's by default), baking only the
// footprints with its own integrator, against the truth there, an eighth of the views at a time,
// left as soon as its error provably exceeds 1.5 x margin * budget (plan/error_sample.h,
// sampled_blend_error: a wide miss costs a fraction of a measurement, and its lower bound
// calibrates the screen as a measurement would, optimistically).
// It is taken when
//
//   e_measured + k s_measured <= margin * budget        (k = options.sigmas)
//
// with s the jackknife standard error over the confirmation's views, once two rounds of views agree:
// the confirmation is a sequential test in rounds of fresh views pooled into one estimate (a miss
// when e - s exceeds the planned budget; undecided in between, when a further round doubles the pooled views,
// up to confirm_max_views; a pass at the first round is measured once more at fresh views, since
// those first views selected it among every candidate before it). The reserve, (1 - margin) *
// budget at the first round's views, shrinks as 1 / sqrt of the views pooled (below: it is for the
// scatter between samples). The jackknife takes the views
// as independent draws, but they are an evenly spread lattice, so it overstates the estimate's
// scatter (1.9x on a synthetic glint, tests/plan/error_sample_test.cpp; about 1.6x between pilot and
// check on the development environments): k = 0.5 adds about one true standard error. That is not
// enough on its own: where a low sun's glint reaches the grazing band of a few views, the estimate
// is heavy-tailed, a sample that misses the tail is low in both its value and its standard error,
// and the plan takes the first candidate that passes, so a low draw is what it selects. The margin
// (0.9 by default) plans to 90% of the budget at the first round's 128 views, a reserve about as
// wide as the confirmation's scatter between seeds there (docs/tradeoffs.md, "Planning for an error
// budget"); at 512 pooled views, to 95%.
//
// The time of a setting: setup(m) + N * disc_texels(r) * t(m), with setup(m) the integrator's
// construction (its precomputation from the environment) and t(m) its wall time per texel, both
// measured in the pilot on this machine with its threads: t(m) from one whole map (as a bake runs
// it), not from the pilot's scattered texels, whose time is mostly per-map overhead; only a setting
// too slow for a 32^2 map in a quarter of a second keeps the scattered texels' time.
//
// The choice: the settings sorted by predicted time; the first that meets the budget. The pilot
// measures e_interp lazily, only for the (N, r) pairs it reaches and that no measured pair with at
// least as many views and texels already rules out, unless asked for every pair; its confirmations
// measure at most max_confirmations candidates' worth of views. When the screen lets none through,
// the candidate with the least screened error is measured if that is within twice the planned
// budget, and when every confirmation stopped early, the one stopped at the least bound is measured
// in full, so that the plan can name the closest setting.
#pragma once

#include "bake/brdf.h"
#include "core/env_map.h"
#include "formats/map_set.h"
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

// The integrator settings a plan considers by default: reference widths 32-256 and full (2x
// apart), mis 16-1024 and fis 8-512 samples (2x apart), sh (Lambert only; left out for other BRDFs).
std::vector<IntegratorSetting> default_integrator_settings();

struct BakeSetting {
  std::string views;  // a ViewSet::named name ("icosa", "42", "162", "642", ...)
  int view_count = 0;
  int res = 0;
  IntegratorSetting integrator;
};

struct BakePlanOptions {
  double max_error = 0.02;  // relative RMS of blends at novel views against direct bakes there
  // Steps of about sqrt 2 in cost: view counts about sqrt 2 apart (the geodesic sets and Fibonacci
  // sets between them), sizes sqrt 2 apart (2x in texels: with the view steps, every sqrt 2 in
  // cost), samples 2x apart; a choice one step past the cheapest that meets the budget costs about
  // 1.4x it, where 2x steps cost 2x.
  std::vector<std::string> view_sets = {"icosa",  "fib24",  "fib34",  "42",  "fib59",  "fib84",   "fib115",  "162",
                                        "fib230", "fib324", "fib460", "642", "fib910", "fib1284", "fib1820", "fib2562"};
  std::vector<int> sizes = {32, 45, 64, 90, 128, 181, 256};
  std::vector<IntegratorSetting> integrators = default_integrator_settings();
  bool normalise_albedo = false;  // plan albedo-normalised maps (core/albedo_normalisation.h)
  // The pilot: novel views, texels per view and the destination size they are drawn from.
  int pilot_views = 32;
  int pilot_texels = 32;
  int pilot_size = 128;
  int guide_size = 32;  // the guide's bake (0: uniform texels, no guide)
  // The pilot's draws and the integrators' seed: plan with the seed the bake will use (a filtered
  // importance sampling bake's error depends on it as much as on its sample count).
  std::uint64_t seed = 1;
  // The confirmations' own sample: confirm_views novel views x pilot_texels (another seed, drawn
  // the same way); 0: the pilot's texels. Four times the pilot's views halve the scatter of the
  // estimate that decides, at four times the cost of each confirmation.
  int confirm_views = 128;
  // A candidate neither clearly within the planned budget nor one standard error over it, and one
  // that passes at its first round, is measured at fresh views in further rounds, each doubling the
  // views it pools, up to this many (bake_plan.cpp, "The rounds"); at most confirm_views: one round.
  int confirm_max_views = 512;
  double sigmas = 0.5;         // k: jackknife standard errors added to the measured error
  int max_confirmations = 32;  // the confirmations' views, in whole candidates, before the plan gives up
  // A setting is taken when its upper bound <= margin * max_error at the first round's views; the
  // reserve (1 - margin) * max_error shrinks as 1 / sqrt of the views pooled (at 4x them, to half).
  double margin = 0.9;
  bool every_pair = false;  // measure e_interp for every (views, size) pair, not only those reached
  // Leave a confirmation once its error provably exceeds 1.5x the planned budget (plan/error_sample.h,
  // sampled_blend_error); false: measure every confirmation at all its views (a fuller table).
  bool stop_early = true;
};

struct IntegratorPilot {
  IntegratorSetting setting;
  double error = 0;              // e_int: relative RMS against the full reference at the pilot texels
  double error_sigma = 0;        // its standard error
  double seconds_per_texel = 0;  // wall time
  double setup_seconds = 0;      // constructing the integrator from the environment
};

struct InterpolationPilot {
  std::string views;
  int view_count = 0;
  int res = 0;
  double error = 0;        // e_interp: raw_error less the FIS maps' own error in quadrature
  double raw_error = 0;    // the FIS maps' blend against FIS direct values
  double error_sigma = 0;  // its standard error
  long long texels = 0;    // source texels baked to measure it
  double seconds = 0;
};

struct PlannedSetting {
  BakeSetting setting;
  double integration_error = 0;
  std::optional<double> interpolation_error;  // nullopt: not measured (not reached)
  double error = 0;                           // the prediction when interpolation_error is known, else e_int alone
  double upper_error = 0;                     // measured + k sigma when measured, else from the model's parts
  std::optional<double> measured_error;       // the set's blend at the confirmation texels (screened in)
  std::optional<double> measured_sigma;       // its standard error
  // A confirmation stopped once its error provably exceeded 1.5x the planned budget: a lower bound
  // of the error it would have measured (measured_error stays nullopt).
  std::optional<double> measured_at_least;
  int measured_views = 0;  // the confirmation views measured (pooled over its rounds; 0: not measured)
  // The screen's optimistic error, hypot(a e_interp, e_int') with e_int' the integration error (b
  // e_int for mis), and the factors it used: a for interpolation (half) and b for mis (a third),
  // until measurements calibrate them to the least that they imply; nullopt: not screened.
  std::optional<double> screened_error;
  double interpolation_screen = 0.5;
  double mis_screen = 1.0 / 3.0;
  double seconds = 0;  // predicted bake time
  bool meets = false;  // measured, and upper_error <= the planned budget at its measured_views
};

struct BakePlan {
  BakePlanOptions options;
  std::vector<IntegratorPilot> integrators;
  std::vector<InterpolationPilot> interpolation;
  IntegratorSetting interpolation_integrator;  // the FIS setting that measured e_interp
  double interpolation_integrator_error = 0;   // its own error at the pilot texels
  std::vector<PlannedSetting> settings;        // every candidate, by predicted time
  std::optional<PlannedSetting> chosen;        // nullopt: no candidate is predicted to meet the budget
  // Without a choice: the measured candidate with the least upper error (nullopt when none was
  // measured), the nearest thing to a setting; it meets a budget of upper_error / margin.
  std::optional<PlannedSetting> closest;
  double pilot_seconds = 0;
  double confirm_seconds = 0;    // of which measuring screened-in candidates
  long long truth_texels = 0;    // reference texels of the pilot's and the confirmations' truth
  long long confirm_texels = 0;  // texels each confirmation is measured at (0: no candidate measured)
  std::string why;               // a few lines for people
  nlohmann::json to_json() const;
};

// The integrators alone, for maps that are not interpolated (baked at the frames they are used at,
// as `rsibr process` bakes the grey ball at the captured views): e_int and the time per texel of
// each setting at 4 x 96 guided texels against the full reference, and the cheapest per texel with
// e_int + its standard error <= margin * max_error (nullopt when none is).
struct IntegratorPlan {
  std::vector<IntegratorPilot> integrators;
  std::optional<IntegratorPilot> chosen;
  double max_error = 0, margin = 1.0, seconds = 0;
  nlohmann::json to_json() const;
};
IntegratorPlan plan_integrator(const EnvMap& env, const Brdf& brdf, double max_error,
                               const std::vector<IntegratorSetting>& settings = default_integrator_settings(),
                               std::uint64_t seed = 1, double margin = 1.0);

// Throws std::invalid_argument for a budget that is not in (0, 1), empty candidate lists, a view set
// or size that cannot be used, and what the integrators throw on construction.
BakePlan plan_bake(const EnvMap& env, const Brdf& brdf, const BakePlanOptions& options);

// The setting a bake for `plan` uses: the chosen one; without a choice, the closest measured one
// when its measured error (the pilot's estimate, without the reserve and the standard errors) is
// within the budget, with *fallback set: no candidate cleared the plan's reserve, but baking the
// nearest one and checking it (check_bake_for_budget, whose verdict then decides) serves a user
// better than nothing; else none (nullptr).
const PlannedSetting* setting_to_bake(const BakePlan& plan, bool* fallback = nullptr);

// The error of a baked set at fresh novel views (seed), measured as the plan predicts it: its blend
// against the full reference quadrature at `views` x `texels` texels drawn with the plan's guide.
struct BakeCheck {
  double error = 0;
  double error_sigma = 0;
  int views = 0, texels = 0;
  double seconds = 0;
};
BakeCheck check_bake(const MapSet& set, const ViewSet& view_set, const EnvMap& env, const Brdf& brdf,
                     std::uint64_t seed, int views = 4, int texels = 96, int size = 128);

// The check against a budget, in rounds until it decides: round k measures check_bake at
// views * 2^k fresh views (seed + k, texels and size as given) and stops at the first of
//   error + sigmas * sigma <= budget  -> "meets"
//   error - sigmas * sigma >  budget  -> "exceeds"
//   sigma <= target_sigma * budget, or max_views reached -> "undecided" (at the budget within its
//   standard error; `error` is still the best estimate)
// A check of a few views scatters widely near the budget (a sun's glint sits in few of them;
// docs/tradeoffs.md, "Planning for an error budget"), so a fixed small check passes or fails a
// setting at the budget by chance; the rounds spend views only where the answer is close. Cost:
// about twice the last round.
struct BakeCheckOptions {
  int views = 8;
  int texels = 96;
  int size = 128;
  int max_views = 64;
  double sigmas = 2;
  double target_sigma = 0.1;
};
struct BudgetCheck {
  BakeCheck check;      // the last round's
  std::string verdict;  // "meets", "exceeds" or "undecided"
  int rounds = 0;
  double seconds = 0;  // all rounds
};
// Throws std::invalid_argument for a budget not > 0, views < 1, max_views < views, texels < 1 or
// sigmas < 0.
BudgetCheck check_bake_for_budget(const MapSet& set, const ViewSet& view_set, const EnvMap& env, const Brdf& brdf,
                                  std::uint64_t seed, double budget, const BakeCheckOptions& options = {});

}  // namespace rsibr
