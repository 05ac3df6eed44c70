// rsibr bake: a computed map set, the lighting integral of a BRDF against an environment, one
// sphere map per view (bake/integrator.h for what a texel holds).
#include "cli/bake_planning.h"
#include "cli/option_checks.h"
#include "cli/render_image.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"

#include "bake/brdf_lobes.h"
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "cluster/distributed_bake.h"
#include "cluster/session.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "core/progress.h"
#include "core/view_set.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace rsibr::cli {
namespace {

struct BakeArgs {
  std::string env, brdf, views = "icosa", method = "mis", layout, json, output, lobe = "all", normalise = "none";
  std::string max_error;  // empty: the settings as given; else plan them (plan/bake_plan.h)
  int res = 128;
  int samples = 64;
  int reference_width = 0;
  std::uint64_t seed = 0;
  bool sanitize = false, quiet = false;
};

// The inputs every rank reads (each rank of an MPI bake reads them itself).
struct BakeInputs {
  EnvMap env;
  std::shared_ptr<const Brdf> brdf;
  ViewSet views;
  std::unique_ptr<Integrator> integrator;  // made from env where it lies (see run_bake)
};

BakeInputs read_bake_inputs(const BakeArgs& a) {
  BakeInputs in{read_environment_input(a.env, a.layout, a.sanitize), load_brdf(a.brdf), ViewSet::named(a.views), {}};
  // --lobe: the whole BRDF, or one part of it (bake/brdf_lobes.h) with its own central direction.
  if (a.lobe != "all") {
    const CentralDirection part = central_direction_from_string(a.lobe);
    if (!in.brdf->has_lobe(part))
      throw std::invalid_argument(a.brdf + ": --lobe " + a.lobe + ": the BRDF has no " + a.lobe + " lobe");
    in.brdf = std::make_shared<BrdfLobe>(in.brdf, part);
  }
  return in;
}

int run_bake(const BakeArgs& given, const CLI::App& command) {
  BakeArgs a = given;  // --max-error replaces the knobs it plans
  if (std::filesystem::path(a.output).extension() != ".exr")
    throw std::invalid_argument(a.output + ": the output must be an .exr file");
  // Under mpirun the ranks split the texels (cluster/distributed_bake.h); the root writes.
  const cluster::Session& session = cluster::Session::current();
  if (!a.max_error.empty() && session.size() > 1)
    throw std::invalid_argument("--max-error plans in one process; run rsibr plan, then mpirun the bake it prints");
  OutputPlan outputs({a.env, a.brdf, a.views});
  const std::string exr = outputs.file(a.output), json = outputs.file(a.json);
  const auto t0 = std::chrono::steady_clock::now();
  // Every rank reads the inputs; when one cannot, every rank stops here rather than wait for it.
  std::optional<BakeInputs> read;
  std::exception_ptr failed;
  try {
    read.emplace(read_bake_inputs(a));
    // Made in place: the integrator keeps what it precomputes from the environment it is given.
    read->integrator = make_integrator(a.method, read->env);
  } catch (...) {
    failed = std::current_exception();
  }
  if (!session.all(!failed)) {
    if (failed) std::rethrow_exception(failed);
    throw std::runtime_error("another rank could not read the inputs");
  }
  BakeInputs& in = *read;
  const EnvMap& env = in.env;

  // --max-error: the knobs the user did not fix are planned from pilot measurements, then the bake
  // runs with the chosen setting and is checked at fresh novel views until the check decides
  // (plan/bake_plan.h, check_bake_for_budget).
  std::optional<BakePlan> plan;
  const PlannedSetting* planned = nullptr;  // plan->chosen, or the closest measured setting
  bool fallback = false;
  if (!a.max_error.empty()) {
    BakeKnobs knobs;
    if (command.count("--views")) knobs.views = a.views;
    if (command.count("--res")) knobs.res = a.res;
    if (command.count("--method")) knobs.method = a.method;
    if (command.count("--samples")) knobs.samples = a.samples;
    if (command.count("--reference-width")) knobs.reference_width = a.reference_width;
    knobs.normalise_albedo = a.normalise == "albedo";
    plan = plan_bake(env, *in.brdf, bake_plan_options(parse_error_budget(a.max_error), knobs, a.seed));
    planned = setting_to_bake(*plan, &fallback);
    if (!planned) {
      std::cerr << "rsibr bake: error: " << a.brdf << ": no setting is predicted to meet --max-error " << a.max_error
                << " under " << a.env << " (rsibr plan shows the candidates); nothing written\n";
      return 3;
    }
    if (fallback) {
      std::ostringstream m;
      m << std::fixed << std::setprecision(2) << "rsibr bake: warning: no setting clears the plan's reserve ("
        << std::lround(100 * plan->options.margin) << "% of --max-error " << a.max_error << " at "
        << plan->options.confirm_views << " views, nearer it at more"
        << "); baking the closest measured one, " << planned->setting.view_count << " views x " << planned->setting.res
        << "^2, " << planned->setting.integrator.label() << " (measured " << 100 * *planned->measured_error << "% +- "
        << 100 * *planned->measured_sigma << "% at " << planned->measured_views
        << " confirmation views), and checking it\n";
      std::cerr << m.str();
    }
    const BakeSetting& s = planned->setting;
    a.views = s.views;
    a.res = s.res;
    a.method = s.integrator.method;
    if (a.method == "mis" || a.method == "fis") a.samples = s.integrator.samples;
    if (a.method == "reference") a.reference_width = s.integrator.reference_width;
    in.views = ViewSet::named(a.views);
    in.integrator = make_integrator(a.method, env);
    if (!a.quiet) std::cerr << "rsibr bake: planned: " << plan->why;
  }
  const Brdf* brdf = in.brdf.get();
  IntegratorOptions options;
  options.samples = a.samples;
  options.seed = a.seed;
  options.reference_width = a.reference_width;
  const auto t1 = std::chrono::steady_clock::now();

  // --normalise albedo: texels hold L / A(n.v), the runtime multiplies A back (core/albedo_normalisation.h).
  MapSetBakeOptions bake_options;
  bake_options.res = a.res;
  bake_options.integrator = options;
  bake_options.normalise_albedo = a.normalise == "albedo";
  bake_options.environment_name = std::filesystem::path(a.env).filename().string();
  const std::string warp = to_string(brdf->central_direction());
  const bool stochastic = a.method == "mis" || a.method == "fis";
  Progress bar("bake", session.is_root() && !a.quiet && Progress::stderr_is_terminal());
  cluster::DistributedBakeTimes times;
  const MapSet set = cluster::bake_map_set_distributed(
      *brdf, *in.integrator, in.views, bake_options, session, [&](double f) { bar.update(f); }, &times);
  bar.done();
  if (!session.is_root()) return 0;
  const auto t2 = std::chrono::steady_clock::now();
  write_map_set(exr, set);
  const auto t3 = std::chrono::steady_clock::now();
  std::optional<BudgetCheck> check;
  if (plan) {
    check = check_bake_for_budget(set, in.views, env, *brdf, a.seed + 1, plan->options.max_error);
    const BakeCheck& k = check->check;
    if (!a.quiet)
      std::cerr << "rsibr bake: checked at " << k.views << " fresh novel views (" << check->rounds
                << (check->rounds == 1 ? " round" : " rounds") << "): " << 100 * k.error << "% +- "
                << 100 * k.error_sigma << "% against the reference (predicted " << 100 * planned->error << "%, budget "
                << 100 * plan->options.max_error << "%): " << check->verdict << "\n";
    if (check->verdict == "exceeds")
      std::cerr << "rsibr bake: warning: the checked error " << 100 * k.error << "% exceeds --max-error " << a.max_error
                << " by more than twice its standard error\n";
    else if (check->verdict == "undecided" && k.error > plan->options.max_error)
      std::cerr << "rsibr bake: warning: the checked error " << 100 * k.error << "% is above --max-error "
                << a.max_error << ", within twice its standard error\n";
  }

  auto secs = [](auto d) { return std::chrono::duration<double>(d).count(); };
  if (!a.quiet)
    std::cerr << "rsibr bake: " << set.views.size() << " views x " << a.res << "^2, " << a.method
              << (stochastic ? " (" + std::to_string(a.samples) + " samples)" : std::string()) << ", " << secs(t2 - t1)
              << " s (" << secs(t2 - t1) / double(set.views.size()) << " s per map"
              << (session.size() > 1 ? ", " + std::to_string(session.size()) + " ranks" : std::string()) << ")\n";
  nlohmann::json j;
  j["output"] = a.output;
  j["environment"] = a.env;
  j["environment_layout"] = to_string(env.layout.kind());
  j["environment_size"] = {env.layout.width(), env.layout.height()};
  j["material"] = brdf->spec();
  j["warp"] = warp;
  j["lobe"] = a.lobe;
  j["normalise"] = a.normalise;
  j["method"] = a.method;
  j["samples"] = a.samples;
  j["seed"] = a.seed;
  j["views"] = set.views.size();
  j["res"] = a.res;
  j["ranks"] = session.size();
  // integrate: the whole bake as the root saw it (its own rows, then the gather); gather: the part
  // of it spent waiting for and receiving the other ranks' rows; root_integrate: the root's own rows.
  j["seconds"] = {{"setup", secs(t1 - t0)}, {"integrate", secs(t2 - t1)},
                  {"write", secs(t3 - t2)}, {"per_map", secs(t2 - t1) / double(set.views.size())},
                  {"gather", times.gather}, {"root_integrate", times.integrate}};
  j["root_rows"] = times.rows;
  if (plan) {
    j["plan"] = plan->to_json();
    const BakeCheck& k = check->check;
    j["check"] = {{"error", k.error},
                  {"error_sigma", k.error_sigma},
                  {"predicted_error", planned->error},
                  {"planned_from", fallback ? "closest" : "chosen"},
                  {"max_error", plan->options.max_error},
                  {"meets", k.error <= plan->options.max_error},
                  {"verdict", check->verdict},
                  {"predicted_seconds", planned->seconds},
                  {"seconds", secs(t2 - t1)},
                  {"views", k.views},
                  {"texels", k.texels},
                  {"rounds", check->rounds},
                  {"check_seconds", check->seconds}};
  }
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_bake(CLI::App& app) {
  auto a = std::make_shared<BakeArgs>();
  CLI::App* c = app.add_subcommand("bake", "Compute a map set: a BRDF lit by an environment, one sphere map per view");
  c->footer(
      "Methods: reference (quadrature over every environment texel; exact, slow), mis (Monte Carlo, BRDF and "
      "environment sampling combined), fis (filtered importance sampling over a MIP pyramid), sh (spherical "
      "harmonics order 2, lambert only). The same inputs and --seed give the same bytes.\n"
      "Multi-lobe maps: --lobe normal and --lobe mirror bake the two parts of a BRDF (clear coat: the binder; "
      "the coat and flakes) as two sets, each warped with its own warp; the runtime sums them "
      "(rsibr render --maps normal.exr --maps mirror.exr).\n"
      "Under mpirun (a build with MPI) the ranks split the maps' texels and the root writes the set: the same "
      "bytes as one process (mpirun -n 8 rsibr bake ...).\n"
      "--normalise albedo stores each texel divided by the BRDF's directional albedo at its n.v (a table in the "
      "file); the runtime multiplies it back at the destination view, so a view dependence through Fresnel "
      "factors is not warped (the clear coat's normal part becomes exactly view independent).");
  c->add_option("output", a->output, "Output map set (.exr)")->required();
  c->add_option("--env", a->env, "Environment map (EXR or .hdr)")->required();
  c->add_option("--brdf", a->brdf, "BRDF spec (YAML)")->required();
  c->add_option("--views", a->views, "View set: tetra, octa, icosa, 42, 162, 642, fibN or a file of 'x y z' lines");
  c->add_option("--res", a->res, "Sphere-map size (square)")->check(CLI::Range(1, 8192));
  c->add_option("--lobe", a->lobe,
                "all (the whole BRDF), or normal / mirror: only that part of it (multi-lobe maps: bake each part "
                "and render with --maps once per part); the warp follows the part")
      ->check(CLI::IsMember({"all", "normal", "mirror"}));
  c->add_option("--normalise", a->normalise, "none, or albedo: albedo-normalised maps (see below)")
      ->check(CLI::IsMember({"none", "albedo"}));
  c->add_option("--method", a->method, "reference, mis, fis or sh")
      ->check(CLI::IsMember({"reference", "mis", "fis", "sh"}));
  c->add_option("--samples", a->samples, "mis, fis: samples per texel")->check(CLI::Range(1, 1 << 20));
  c->add_option("--seed", a->seed, "Random seed (mis, fis)")->check(seed_check());
  c->add_option("--reference-width", a->reference_width,
                "reference: integrate over the MIP level at most this wide (0: the full environment)")
      ->check(CLI::Range(0, 1 << 20));
  c->add_option("--layout", a->layout, "Layout of the environment when its header and shape do not tell");
  c->add_flag(
      "--sanitize", a->sanitize,
      "Zero NaN, Inf and absurd environment values instead of failing (negative values are always folded into their positive neighbours, energy kept)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or summary line");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_option("--max-error", a->max_error,
                "Plan the knobs not given (views, res, method, samples) for this error budget at novel views, "
                "e.g. 2% (see rsibr plan --help); the result is checked at fresh novel views, 8 then twice as many "
                "(up to 64) until it meets or exceeds the budget by twice its standard error or is within 10% of it: "
                "verdict meets, exceeds or undecided, in --json")
      ->check(error_budget_check());
  return [a, c] { return run_bake(*a, *c); };
}

}  // namespace rsibr::cli
