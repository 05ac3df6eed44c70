// rsibr export blender: a process run as a Blender scene (export/blender_scene.h). The .blend is
// written by Blender itself: rsibr writes the scene description, the world, the photos and the
// script, and runs `blender -b` on them. Why not write .blend bytes here: the format is Blender's
// memory dump, undocumented and versioned with it; its own Python API is the stable way in.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "core/atomic_folder.h"
#include "core/output_plan.h"
#include "core/progress.h"
#include "export/blender_scene.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <iterator>

extern char** environ;

namespace rsibr::cli {
namespace {

namespace fs = std::filesystem;

struct ExportArgs {
  std::string run, out, blender, json;
  int samples = 256, world_width = 0, preview_samples = 0;
  bool no_blend = false, quiet = false;
};

// The Blender program: --blender, else $RSIBR_BLENDER, else `blender` on PATH.
std::string blender_program(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* e = std::getenv("RSIBR_BLENDER"); e && *e) return e;
  return "blender";
}

// Runs Blender with `args`, its output into `log`. Throws std::runtime_error with the log's last
// line when it fails, std::invalid_argument when it cannot be started.
void run_blender(const std::string& program, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> words = {program, "-b", "--factory-startup", "--python-exit-code", "3"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw std::invalid_argument("cannot run Blender ('" + program +
                                "'; install Debian's blender, give --blender PATH, or --no-blend for the script only)");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("waiting for Blender failed");
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find("rror") != std::string::npos || line.find("build_blender_scene.py:") != std::string::npos)
      last = line;
  throw std::runtime_error("Blender failed (" +
                           (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status)) : std::string("killed")) +
                           ")" + (last.empty() ? std::string() : ": " + last));
}

void write_bytes(const fs::path& file, const std::vector<unsigned char>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
}

std::vector<unsigned char> read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int run_export_blender(const ExportArgs& a) {
  if (!fs::is_directory(a.run)) throw std::invalid_argument(a.run + ": not a folder (give rsibr process's DIR)");
  OutputPlan outputs({fs::path(a.run)});
  outputs.folder(a.out);
  const std::string json = outputs.file(a.json);
  check_output_folder(a.out, {fs::path(a.run)});
  BlenderExportOptions options;
  options.samples = a.samples;
  options.world_width = a.world_width;
  const BlenderExport scene = blender_export_from_run(a.run, options);
  const std::string program = blender_program(a.blender);

  // Everything is made in a staging folder beside OUT (Blender writes files), then moved in at once.
  const fs::path target = fs::absolute(a.out).lexically_normal();
  const fs::path staging =
      target.parent_path() / ("." + target.filename().string() + ".export" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  FolderContents files;
  try {
    for (const auto& [name, bytes] : scene.files) write_bytes(staging / name, bytes);
    const std::string scene_json = blender_scene_json(scene).dump(2) + "\n";
    write_bytes(staging / "scene.json", std::vector<unsigned char>(scene_json.begin(), scene_json.end()));
    const std::string script = blender_scene_script();
    write_bytes(staging / "build_blender_scene.py", std::vector<unsigned char>(script.begin(), script.end()));
    if (!a.no_blend) {
      const fs::path log = staging / "blender.log";
      std::vector<std::string> args = {"--python",
                                       (staging / "build_blender_scene.py").string(),
                                       "--",
                                       "--scene",
                                       (staging / "scene.json").string(),
                                       "--blend",
                                       (staging / "scene.blend").string()};
      if (a.preview_samples > 0) {
        args.insert(args.end(), {"--render", "1", "--samples", std::to_string(a.preview_samples), "--image",
                                 (staging / "preview.png").string()});
      }
      if (!a.quiet && Progress::stderr_is_terminal()) std::cerr << "rsibr export: running Blender...\n";
      run_blender(program, args, log);
      fs::remove(log);
    }
    for (const auto& entry : fs::directory_iterator(staging))
      if (entry.is_regular_file()) files[entry.path().filename().string()] = read_bytes(entry.path());
  } catch (...) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    throw;
  }
  fs::remove_all(staging);
  write_folder_atomically(target, files);

  nlohmann::json j = {{"run", a.run},
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
      "Example: rsibr export blender run --out run-blender && blender run-blender/scene.blend");
  b->add_option("run", a->run, "rsibr process's DIR (after its bake step)")->required();
  b->add_option("--out", a->out, "Output folder")->required();
  b->add_option("--blender", a->blender, "The Blender program (default $RSIBR_BLENDER, else blender on PATH)");
  b->add_option("--samples", a->samples, "Cycles samples per pixel set in the scene (default 256)")
      ->check(CLI::Range(1, 1 << 20));
  b->add_option("--world-width", a->world_width, "Width of world.exr (default the probe's)")
      ->check(CLI::Range(0, 65536));
  b->add_option("--preview", a->preview_samples,
                "Also render frame 1 over its photo at this many samples into OUT/preview.png")
      ->check(CLI::Range(1, 1 << 20));
  b->add_flag("--no-blend", a->no_blend, "Write the scene, world, photos and script but do not run Blender");
  b->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  b->add_flag("-q,--quiet", a->quiet, "No progress or summary line");
  return [a, b] { return b->parsed() ? run_export_blender(*a) : 2; };
}

}  // namespace rsibr::cli
