// An export folder for Blender: the scene's files, scene.json and the Blender-side script, and
// the .blend that Blender builds from them (rsibr export blender; tests render from it).
#pragma once

#include "export/blender_scene.h"

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

// The Blender program: `given`, else $RSIBR_BLENDER, else `blender` on PATH.
std::string blender_program(const std::string& given = "");

// Runs `program -b --factory-startup --python-exit-code 3 ARGS...`, its output appended to `log`.
// Throws std::invalid_argument when it cannot be started, std::runtime_error("Blender failed
// (exit N): <the log's last error line>") when it fails.
void run_blender(const std::string& program, const std::vector<std::string>& args, const std::filesystem::path& log);

struct BlenderFolderOptions {
  std::string program;      // for blender_program
  bool build_blend = true;  // run Blender to write scene.blend
  int preview_samples = 0;  // > 0: also render frame 1 into preview.png at this many samples
};

// Writes the scene into `folder` (existing): its files, scene.json, build_blender_scene.py, and
// (build_blend) scene.blend and preview.png through Blender; Blender's log is removed when it
// succeeds and left as blender.log when it fails.
void write_blender_folder(const BlenderExport& scene, const std::filesystem::path& folder,
                          const BlenderFolderOptions& options);

}  // namespace rsibr
