// rsibr plan: the cheapest bake setting (views, map size, integrator and samples) whose maps,
// blended to any view, stay within an error budget of the direct bake there, predicted from pilot
// measurements on the user's own environment and BRDF (plan/bake_plan.h).
#include "cli/bake_planning.h"
#include "cli/option_checks.h"
#include "cli/render_image.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "bake/brdf_lobes.h"
#include "bake/brdf_spec.h"
#include "formats/output_plan.h"

#include <iostream>
#include <memory>

namespace rsibr::cli {
namespace {

struct PlanArgs {
  std::string env, brdf, layout, json, max_error, views, method, lobe = "all", normalise = "none";
  int res = 0, samples = 0, reference_width = -1;
  int confirm_views = BakePlanOptions{}.confirm_views;
  int confirm_max_views = BakePlanOptions{}.confirm_max_views;
  std::uint64_t seed = 0;  // rsibr bake's default: a plan holds for the seed it was made with
  bool sanitize = false, every_pair = false;
};

// The default candidates, from the planner's own lists: "view sets icosa, fib24, ...; sizes ...; ...".
std::string candidates_text() {
  const BakePlanOptions defaults;
  auto join = [](const auto& items, auto text) {
    std::string out;
    for (const auto& item : items) out += (out.empty() ? "" : ", ") + text(item);
    return out;
  };
  return "view sets " + join(defaults.view_sets, [](const std::string& v) { return v; }) + "; sizes " +
         join(defaults.sizes, [](int r) { return std::to_string(r); }) + "; integrators " +
         join(defaults.integrators, [](const IntegratorSetting& i) { return i.label(); }) + " (sh for Lambert only)";
}

int run_plan(const PlanArgs& a) {
  OutputPlan outputs({a.env, a.brdf});
  const std::string json = outputs.file(a.json);
  BakeKnobs knobs;
  if (!a.views.empty()) knobs.views = a.views;
  if (a.res > 0) knobs.res = a.res;
  if (!a.method.empty()) knobs.method = a.method;
  if (a.samples > 0) knobs.samples = a.samples;
  if (a.reference_width >= 0) knobs.reference_width = a.reference_width;
  knobs.normalise_albedo = a.normalise == "albedo";
  BakePlanOptions options = bake_plan_options(parse_error_budget(a.max_error), knobs, a.seed);
  options.every_pair = a.every_pair;
  options.confirm_views = a.confirm_views;
  options.confirm_max_views = a.confirm_max_views;
  if (knobs.views) ViewSet::named(*knobs.views);  // a bad --views is refused before the pilot
  const EnvMap env = read_environment_input(a.env, a.layout, a.sanitize);
  std::shared_ptr<const Brdf> brdf = load_brdf(a.brdf);
  if (a.lobe != "all") brdf = std::make_shared<BrdfLobe>(brdf, central_direction_from_string(a.lobe));
  const BakePlan plan = plan_bake(env, *brdf, options);
  std::ostream& out = a.json == "-" ? std::cerr : std::cout;
  print_plan(out, plan);
  bool fallback = false;
  const PlannedSetting* to_bake = setting_to_bake(plan, &fallback);
  if (to_bake)
    out << (fallback ? "none clears the reserve; rsibr bake --max-error would bake the closest measured setting "
                       "and check it: rsibr bake"
                     : "bake it: rsibr bake")
        << " --env " << a.env << " --brdf " << a.brdf << " " << bake_arguments(to_bake->setting)
        << (a.lobe != "all" ? " --lobe " + a.lobe : "") << (knobs.normalise_albedo ? " --normalise albedo" : "")
        << (a.seed != 0 ? " --seed " + std::to_string(a.seed) : "") << " OUTPUT.exr\n";
  nlohmann::json j = plan.to_json();
  j["environment"] = a.env;
  j["brdf"] = a.brdf;
  j["material"] = brdf->spec();
  if (to_bake)
    j[fallback ? "closest_bake_arguments" : "bake_arguments"] =
        bake_arguments(to_bake->setting) + (a.seed != 0 ? " --seed " + std::to_string(a.seed) : "");
  write_summary(json, j);
  outputs.commit();
  return plan.chosen ? 0 : 3;
}

}  // namespace

Runner add_plan(CLI::App& app) {
  auto a = std::make_shared<PlanArgs>();
  CLI::App* c = app.add_subcommand(
      "plan", "The cheapest bake setting that meets an error budget, predicted from pilot measurements");
  c->footer(
      "The error is the relative RMS of the set's maps blended to novel views against the BRDF baked directly at "
      "those views with the full reference quadrature (the paper's use of a set), over the disc where n.v >= 0.1 "
      "(the outermost 1% of its area, where every source is faded, is left out). The pilot measures each "
      "integrator's own error and time per texel at a few hundred random texels of random novel views, and the "
      "warp and blend's error for each view set and map size from blends of maps baked only where the blend reads "
      "them; the root sum of squares of the two screens the candidates in order of predicted time, and each one "
      "it lets through is blended at 128 further novel views with its own integrator (left as soon as its error "
      "provably exceeds 1.5 x 90% of the budget): the first whose measured error plus half its standard error is within "
      "90% of the budget is chosen, once 128 fresh views pooled with those agree; one within a standard error of "
      "that reserve is measured at fresh views, doubling them up to --confirm-max-views, until the rule decides "
      "(the reserve shrinks as one over the square root of the views pooled: 95% of the budget at 512). "
      "Candidates: " +
      candidates_text() +
      ". --views, --res, --method, --samples and --reference-width fix a knob. rsibr bake --max-error plans, bakes "
      "and checks the result.\n"
      "Exit status: 0 with a setting, 3 when no candidate is predicted to meet the budget (the plan then names the "
      "closest measured setting and the budget it would meet).\n"
      "Example: rsibr plan --env sky.exr --brdf copper.yaml --max-error 2%");
  c->add_option("--env", a->env, "Environment map (EXR or .hdr)")->required();
  c->add_option("--brdf", a->brdf, "BRDF spec (YAML)")->required();
  c->add_option("--max-error", a->max_error, "The error budget: a relative RMS such as 0.02 or 2%")
      ->required()
      ->check(error_budget_check());
  c->add_option("--views", a->views, "Fix the view set (tetra, octa, icosa, 42, 162, 642, fibN or a file)");
  c->add_option("--res", a->res, "Fix the map size")->check(CLI::Range(2, 8192));
  c->add_option("--method", a->method, "Fix the integrator: reference, mis, fis or sh")
      ->check(CLI::IsMember({"reference", "mis", "fis", "sh"}));
  c->add_option("--samples", a->samples, "With --method mis or fis: fix the samples")->check(CLI::Range(1, 1 << 20));
  c->add_option("--reference-width", a->reference_width, "With --method reference: fix the width (0: full)")
      ->check(CLI::Range(0, 1 << 20));
  c->add_option("--lobe", a->lobe, "all, or normal / mirror: plan one part of the BRDF (as rsibr bake --lobe)")
      ->check(CLI::IsMember({"all", "normal", "mirror"}));
  c->add_option("--normalise", a->normalise, "none, or albedo: plan albedo-normalised maps")
      ->check(CLI::IsMember({"none", "albedo"}));
  c->add_option("--seed", a->seed,
                "Seed of the pilot's novel views and texels and of the stochastic integrators; bake with the same "
                "seed (a FIS bake's error depends on it)")
      ->check(seed_check());
  c->add_flag("--every-pair", a->every_pair,
              "Measure the interpolation error of every view set and size (a fuller table; slower)");
  c->add_option("--confirm-views", a->confirm_views,
                "Novel views of the sample the candidates are confirmed at (0: the pilot's own 32); more views "
                "halve the decision's scatter per 4x, at that much more time per confirmation")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  c->add_option("--confirm-max-views", a->confirm_max_views,
                "Views a confirmation may pool: a candidate within a standard error of the budget, or one that "
                "passes at its first views, is measured again at fresh views, doubling them up to this many "
                "(at most --confirm-views: one round)")
      ->check(CLI::Range(0, 1 << 16))
      ->capture_default_str();
  c->add_option("--layout", a->layout, "Layout of the environment when its header and shape do not tell");
  c->add_flag(
      "--sanitize", a->sanitize,
      "Zero NaN, Inf and absurd environment values instead of failing (negative values are always folded into their positive neighbours, energy kept)");
  c->add_option("--json", a->json, "Write the plan as JSON to FILE ('-' for stdout)");
  return [a] { return run_plan(*a); };
}

}  // namespace rsibr::cli
