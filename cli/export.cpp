// rsibr export blender: a process run as a Blender scene (export/blender_scene.h). The .blend is
// written by Blender itself: rsibr writes the scene description, the world, the photos and the
// script, and runs `blender -b` on them. Why not write .blend bytes here: the format is Blender's
// memory dump, undocumented and versioned with it; its own Python API is the stable way in.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_folder.h"
#include "formats/output_plan.h"
#include "core/progress.h"
#include "formats/exr_io.h"
#include "formats/input_file.h"
#include "formats/map_set.h"
#include "export/blender_folder.h"
#include "export/blender_scene.h"

#include <unistd.h>

#include <fstream>
#include <iostream>
#include <iterator>

namespace rsibr::cli {
namespace {

namespace fs = std::filesystem;

struct ExportArgs {
  std::string run, maps, env, out, blender, json;
  int samples = 256, world_width = 0, preview_samples = 0;
  bool no_blend = false, quiet = false;
};

std::vector<unsigned char> read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int run_export_blender(const ExportArgs& a) {
  if (a.run.empty() == a.maps.empty())
    throw std::invalid_argument(a.run.empty() ? "give a process run (DIR) or a map set (--maps with --env)"
                                              : "give a process run or --maps, not both");
  if (!a.maps.empty() && a.env.empty())
    throw std::invalid_argument("--maps: needs --env (the environment it was baked under)");
  if (a.maps.empty() && !a.env.empty())
    throw std::invalid_argument("--env: only with --maps (a run's world is its probe)");
  if (!a.run.empty() && !fs::is_directory(a.run))
    throw std::invalid_argument(a.run + ": not a folder (give rsibr process's DIR)");
  std::vector<fs::path> inputs;
  for (const std::string& p : {a.run, a.maps, a.env})
    if (!p.empty()) inputs.push_back(p);
  OutputPlan outputs(inputs);
  outputs.folder(a.out);
  const std::string json = outputs.file(a.json);
  check_output_folder(a.out, inputs);
  BlenderExportOptions options;
  options.samples = a.samples;
  options.world_width = a.world_width;
  BlenderExport scene;
  if (!a.run.empty()) {
    scene = blender_export_from_run(a.run, options);
  } else {
    require_regular_file(a.maps);
    require_regular_file(a.env);
    EnvReadReport report;
    EnvMap env = read_environment(a.env, std::nullopt, &report);
    const std::string warning = fold_environment_ringing(env, a.env, report, false);
    if (!warning.empty() && !a.quiet) std::cerr << "rsibr: warning: " << warning << "\n";
    scene = blender_export_from_map_set(read_map_set(a.maps), env, a.maps, options);
  }

  // Everything is made in a staging folder beside OUT (Blender writes files), then moved in at once.
  const fs::path target = fs::absolute(a.out).lexically_normal();
  const fs::path staging =
      target.parent_path() / ("." + target.filename().string() + ".export" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  FolderContents files;
  try {
    BlenderFolderOptions run;
    run.program = a.blender;
    run.build_blend = !a.no_blend;
    run.preview_samples = a.preview_samples;
    if (run.build_blend && !a.quiet && Progress::stderr_is_terminal())
      std::cerr << "rsibr export: running Blender...\n";
    write_blender_folder(scene, staging, run);
    for (const auto& entry : fs::directory_iterator(staging))
      if (entry.is_regular_file()) files[entry.path().filename().string()] = read_bytes(entry.path());
  } catch (...) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    throw;
  }
  fs::remove_all(staging);
  write_folder_atomically(target, files);

  nlohmann::json j = {{"run", a.run.empty() ? nlohmann::json() : nlohmann::json(a.run)},
                      {"maps", a.maps.empty() ? nlohmann::json() : nlohmann::json(a.maps)},
                      {"out", a.out},
                      {"blend", a.no_blend ? nlohmann::json() : nlohmann::json("scene.blend")},
                      {"cameras", scene.cameras.size()},
                      {"balls", scene.balls.size()},
                      {"notes", scene.notes}};
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-") {
    std::cerr << scene.cameras.size() << " cameras, " << scene.balls.size() << " balls -> " << a.out
              << (a.no_blend
                      ? "/scene.json (build it: blender -b --python " + a.out + "/build_blender_scene.py -- --scene " +
                            a.out + "/scene.json --blend " + a.out + "/scene.blend)"
                      : "/scene.blend")
              << "\n";
    for (const std::string& n : scene.notes) std::cerr << "rsibr export: " << n << "\n";
  }
  return 0;
}

}  // namespace

Runner add_export(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  CLI::App* c = app.add_subcommand("export", "Write a run as another program's scene (blender)");
  c->require_subcommand(1);
  CLI::App* b = c->add_subcommand("blender", "A process run as a Blender scene (.blend) that Cycles renders");
  b->footer(
      "OUT gets scene.blend (written by Blender, found as --blender, $RSIBR_BLENDER or 'blender' on PATH), and what it "
      "refers to by relative paths: world.exr (the probe as Blender's World: an equirectangular image in Blender's "
      "cell-centred convention, so Blender sees the radiance rsibr's probe holds), photo_NNNN.exr (each view's merged "
      "photo, scene-linear, undistorted to the camera's pinhole), fresnel-<ball>.exr (the chrome's Fresnel table); "
      "scene.json and build_blender_scene.py, which rebuild the .blend (--no-blend: only these).\n"
      "The scene is Blender's +Z-up world: rsibr's (x, y, z) is Blender's (z, x, y). The chrome ball is at the origin "
      "with the photo set's radius (5 cm when none was listed), each view's camera on its solved pose with the lens's "
      "focal length and principal point (timeline frame i is camera i; the compositor lays the render over photo i), "
      "the grey ball at its solved place as a Lambert of the run's albedo, the chrome as a mirror with the run's "
      "conductor Fresnel. Rendering frame i in Cycles puts the balls on photo i's balls.\n"
      "--maps M --env E instead of a run: the sphere map set M as a scene (a unit sphere with M's material, lit by E "
      "as rsibr reads it, converted like the probe; camera i on view i's frame, orthographic, 2 wide, each pixel its "
      "centre): Cycles' render of frame i is view i's map computed by another renderer.\n"
      "Example: rsibr export blender run --out run-blender && blender run-blender/scene.blend");
  b->add_option("run", a->run, "rsibr process's DIR (after its bake step)");
  b->add_option("--maps", a->maps,
                "Instead of a run: a computed map set; its views of a unit sphere with its material (Lambert, GGX), "
                "one orthographic camera per view, so frame i renders view i's sphere map");
  b->add_option("--env", a->env, "--maps: the environment the maps were baked under (the world)");
  b->add_option("--out", a->out, "Output folder")->required();
  b->add_option("--blender", a->blender, "The Blender program (default $RSIBR_BLENDER, else blender on PATH)");
  b->add_option("--samples", a->samples, "Cycles samples per pixel set in the scene (default 256)")
      ->check(CLI::Range(1, 1 << 20));
  b->add_option("--world-width", a->world_width, "Width of world.exr (default the probe's)")
      ->check(CLI::Range(0, 16384));
  b->add_option("--preview", a->preview_samples,
                "Also render frame 1 over its photo at this many samples into OUT/preview.png")
      ->check(CLI::Range(1, 1 << 20));
  b->add_flag("--no-blend", a->no_blend, "Write the scene, world, photos and script but do not run Blender");
  b->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  b->add_flag("-q,--quiet", a->quiet, "No progress or summary line");
  return [a, b] { return b->parsed() ? run_export_blender(*a) : 2; };
}

}  // namespace rsibr::cli
