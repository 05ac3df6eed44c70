// rsibr synth: a synthetic capture (photo set) of a ball rig with its ground truth
// (capture/synth_capture.h; the scene spec is documented in datasets-synthetic/README.md).
#include "cli/option_checks.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "formats/output_plan.h"
#include "core/progress.h"

#include <iostream>
#include <memory>
#include <optional>

namespace rsibr::cli {
namespace {

struct SynthArgs {
  std::string scene, out, json;
  std::optional<std::uint64_t> seed;
  bool quiet = false;
};

int run_synth(const SynthArgs& a) {
  SynthScene scene = load_synth_scene(a.scene);
  OutputPlan outputs({a.scene});
  outputs.folder(a.out);
  const std::string json = outputs.file(a.json);
  if (a.seed) scene.seed = *a.seed;
  Progress bar("synth", !a.quiet && Progress::stderr_is_terminal());
  const SynthReport r = write_synth_capture(scene, a.out, [&](double f) { bar.update(f); });
  bar.done();
  if (!a.quiet)
    std::cerr << "rsibr synth: " << r.views << " views x " << (r.views ? r.brackets / r.views : 0) << " brackets, "
              << r.chessboards << " chessboards, " << scene.camera.lens.width() << "x" << scene.camera.lens.height()
              << ", " << r.seconds_total << " s (render " << r.seconds_render << " s, brackets " << r.seconds_brackets
              << " s)\n";
  nlohmann::json j;
  j["scene"] = a.scene;
  j["out"] = a.out;
  j["photoset"] = (std::filesystem::path(a.out) / "photos" / "photoset.yaml").string();
  j["truth"] = (std::filesystem::path(a.out) / "truth" / "truth.yaml").string();
  j["seed"] = scene.seed;
  j["views"] = r.views;
  j["brackets"] = r.brackets;
  j["chessboards"] = r.chessboards;
  j["size"] = {scene.camera.lens.width(), scene.camera.lens.height()};
  j["lens"] = scene.camera.lens.name();
  j["supersampling"] = scene.camera.supersampling;
  j["gain"] = r.gain;
  j["samples_traced"] = r.pixels_rendered;
  j["seconds"] = {{"render", r.seconds_render},
                  {"brackets", r.seconds_brackets},
                  {"truth", r.seconds_truth},
                  {"total", r.seconds_total}};
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_synth(CLI::App& app) {
  auto a = std::make_shared<SynthArgs>();
  CLI::App* c = app.add_subcommand("synth", "Synthesize a photo set of a ball rig with its ground truth");
  c->footer(
      "Writes OUT/photos (photoset.yaml, bracketed images, chessboards) and OUT/truth (truth.yaml, "
      "camera.cameramodel, response.csv, linear radiance EXRs per view, true sphere maps per ball, chessboard "
      "corners). The scene spec format: datasets-synthetic/README.md. The same spec and --seed give the same "
      "bytes.");
  c->add_option("scene", a->scene, "Scene spec (YAML)")->required();
  c->add_option("--out", a->out, "Output folder (must not exist, or be empty)")->required();
  c->add_option("--seed", a->seed, "Random seed (overrides the spec's seed)")->check(seed_check());
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or summary line");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] { return run_synth(*a); };
}

}  // namespace rsibr::cli
