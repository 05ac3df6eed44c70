// A process run (rsibr process's DIR) as a Blender scene: the probe as the world, a camera per
// posed view at its solved place with its intrinsics and its (undistorted) merged photo, and the
// balls at their solved places with the run's materials (the chrome ball a mirror with the run's
// conductor Fresnel, the grey ball a Lambert with the run's albedo).
//
// Geometry: the chrome ball's centre is the origin (as in rsibr's rig) and its radius the photo
// set's listed one (5 cm when none was listed, as the extract step assumed); each camera sits
// along its chrome-ball cone at radius / sin(half angle); the other balls at the rig's offsets.
// Every position and rotation in the scene is in Blender's world (export/blender_axes.h).
#pragma once

#include "core/vec.h"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace rsibr {

struct BlenderCamera {
  std::string name;       // the view's name
  Vec3 location;          // Blender world, metres
  Mat3 rotation;          // columns: camera x right, y up, z backward (Blender world)
  double fx = 0, fy = 0;  // pixels
  double cx = 0, cy = 0;  // pixels, mrcal's convention ((0, 0) is the top-left pixel's centre)
  int width = 0, height = 0;
  double near = 0, far = 0;  // clipping distances, metres
  std::string photo;         // file in the export folder
};

struct BlenderBall {
  std::string name;
  std::string kind;  // "chrome" or "grey"
  Vec3 centre;       // Blender world, metres
  double radius = 0;
  Vec3 albedo = Vec3::Zero();  // grey: the Lambert albedo
  std::string fresnel_table;   // chrome: file in the export folder
};

// The scene and the files it refers to (name in the export folder -> bytes).
struct BlenderExport {
  std::vector<BlenderCamera> cameras;
  std::vector<BlenderBall> balls;
  double exposure_stops = 0;  // the run's display exposure
  int samples = 256;          // Cycles samples per pixel
  std::map<std::string, std::vector<unsigned char>> files;
  std::vector<std::string> notes;  // what was left out and why
};

struct BlenderExportOptions {
  int world_width = 0;  // the world image's width (height = width / 2); 0: the probe's
  int samples = 256;
};

// Reads the run's poses.yaml, lens.cameramodel, probe.exr, hdr/<view>.exr, maps/computed-*.exr
// and steps/{extract,probe,render}.json. Throws std::invalid_argument("<file>: <problem>") when
// the run lacks what the scene needs (a run that has not reached its bake step).
BlenderExport blender_export_from_run(const std::filesystem::path& run, const BlenderExportOptions& options = {});

// scene.json (version 1), read by export/build_blender_scene.py.
nlohmann::json blender_scene_json(const BlenderExport& scene);

// The Blender-side script (export/build_blender_scene.py), compiled into the library.
const char* blender_scene_script();

// The table of F(cos) a chrome material looks up: n texels, texel k at cos = (k + 0.5) / n, RGB.
std::vector<Vec3> fresnel_table(const std::string& fresnel_spec, int n = 256);

}  // namespace rsibr
