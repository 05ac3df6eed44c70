#include "export/blender_folder.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

extern char** environ;

namespace rsibr {
namespace {

namespace fs = std::filesystem;

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace

std::string blender_program(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* e = std::getenv("RSIBR_BLENDER"); e && *e) return e;
  return "blender";
}

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

void write_blender_folder(const BlenderExport& scene, const fs::path& folder, const BlenderFolderOptions& options) {
  for (const auto& [name, bytes] : scene.files) write_bytes(folder / name, std::string(bytes.begin(), bytes.end()));
  write_bytes(folder / "scene.json", blender_scene_json(scene).dump(2) + "\n");
  write_bytes(folder / "build_blender_scene.py", blender_scene_script());
  if (!options.build_blend) return;
  const fs::path log = folder / "blender.log";
  std::vector<std::string> args = {"--python",
                                   (folder / "build_blender_scene.py").string(),
                                   "--",
                                   "--scene",
                                   (folder / "scene.json").string(),
                                   "--blend",
                                   (folder / "scene.blend").string()};
  if (options.preview_samples > 0)
    args.insert(args.end(), {"--render", "1", "--samples", std::to_string(options.preview_samples), "--image",
                             (folder / "preview.png").string()});
  run_blender(blender_program(options.program), args, log);
  fs::remove(log);
}

}  // namespace rsibr
