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

#include "core/env_map.h"
#include "formats/map_set.h"
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
  std::string photo;         // file in the export folder; "" for none
  double orthographic = 0;   // > 0: an orthographic camera this wide (metres); intrinsics unused
};

struct BlenderBall {
  std::string name;
  std::string kind;  // "chrome", "grey" or "sphere" (a map set's material)
  Vec3 centre;       // Blender world, metres
  double radius = 0;
  std::string material = "diffuse";  // "diffuse" (Lambert) or "glossy" (Cycles' Glossy BSDF, F = 1)
  Vec3 colour = Vec3::Ones();        // diffuse: the albedo; glossy: a tint
  double roughness = 0;              // glossy: Cycles' roughness, sqrt(GGX alpha); 0: a mirror
  std::string fresnel_table;         // glossy: file in the export folder tinting by F(n.v); "" for none
  bool exact = false;                // an exact sphere (a point-cloud point) instead of an editable UV-sphere mesh
};

// The scene and the files it refers to (name in the export folder -> bytes).
struct BlenderExport {
  std::vector<BlenderCamera> cameras;
  std::vector<BlenderBall> balls;
  double exposure_stops = 0;   // the run's display exposure
  int samples = 256;           // Cycles samples per pixel
  bool pixel_centres = false;  // each pixel the radiance at its centre (sphere maps), not its area
  std::map<std::string, std::vector<unsigned char>> files;
  std::vector<std::string> notes;  // what was left out and why
};

struct BlenderExportOptions {
  int world_width = 0;  // the world image's width (height = width / 2); 0: twice the environment's,
                        // at most 8192 (Cycles' bilinear lookup of rsibr's resampling blurs less)
  int samples = 256;
};

// Reads the run's poses.yaml, lens.cameramodel, balls.json, probe.exr, hdr/<view>.exr, maps/computed-*.exr
// and steps/{extract,probe,render}.json. Throws std::invalid_argument("<file>: <problem>") when
// the run lacks what the scene needs (a run that has not reached its bake step).
BlenderExport blender_export_from_run(const std::filesystem::path& run, const BlenderExportOptions& options = {});

// A map set's views of a sphere (radius 1 at the origin) with the set's material, lit by `env`
// (as rsibr read it: ringing folded): one orthographic camera per view on the view's frame, the
// image as wide as the ball, each pixel its centre, so Cycles renders each view's sphere map.
// Materials: Lambert; GGX (Cycles' GGX masks with the separable Smith form, rsibr's with the
// height-correlated one: up to 1% darker at the rim of a rough ball) with its Fresnel as a tint by
// F(n.v) (exact for a mirror, an approximation for a rough lobe). Others throw
// std::invalid_argument(`what`: ...). `what` names the map set in errors.
BlenderExport blender_export_from_map_set(const MapSet& maps, const EnvMap& env, const std::string& what,
                                          const BlenderExportOptions& options = {});

// scene.json (version 1), read by export/build_blender_scene.py.
nlohmann::json blender_scene_json(const BlenderExport& scene);

// The Blender-side script (export/build_blender_scene.py), compiled into the library.
const char* blender_scene_script();

// The table of F(cos) a chrome material looks up: n texels, texel k at cos = (k + 0.5) / n, RGB.
std::vector<Vec3> fresnel_table(const std::string& fresnel_spec, int n = 256);

}  // namespace rsibr
