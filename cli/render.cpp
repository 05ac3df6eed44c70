// rsibr render: draws a mesh with one or more map sets (runtime/renderer.h) from the shared camera
// options (cli/camera_options.h); PNG through the OpenColorIO display transform, or RGBA float EXR.
#include "cli/camera_options.h"
#include "cli/render_image.h"
#include "cli/rgba_png.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "formats/output_plan.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/text.h"
#include "runtime/make_warp.h"
#include "runtime/renderer.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

namespace rsibr::cli {
namespace {

struct RenderArgs {
  std::vector<std::string> maps;
  std::string mesh, output, mode = "per-pixel", warp = "precomputed", env, json;
  CameraArgs camera;
  int map_size = 0, rings = 16, spp = 1;
  bool lod = false;
  double rim_fade = 0.4;
  std::optional<float> exposure;  // nullopt: metered on the first frame (core/preview_exposure.h)
  bool quiet = false, sanitize = false;
};

std::string extension_of(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

int run_render(const RenderArgs& a) {
  const std::string ext = extension_of(a.output);
  if (ext != ".png" && ext != ".exr") throw std::invalid_argument(a.output + ": the output must be .png or .exr");
  if (a.mode != "paper" && a.mode != "per-pixel")
    throw std::invalid_argument("--mode must be 'paper' or 'per-pixel', not '" + a.mode + "'");
  const int side = int(std::lround(std::sqrt(double(a.spp))));
  if (side * side != a.spp)
    throw std::invalid_argument("--spp must be a perfect square (1, 4, 9, ...), not " + std::to_string(a.spp));
  RenderOptions options;
  options.mode = render_mode_from_string(a.mode);
  options.map_size = a.map_size;
  options.warp = a.warp;
  options.rings = a.rings;
  options.blend.rim_fade = a.rim_fade;
  options.spp = a.spp;
  options.lod = a.lod;
  if (!is_warp_name(a.warp))
    throw std::invalid_argument(std::string("--warp must be ") + warp_names() + ", not '" + a.warp + "'");

  // Every output is checked before any work.
  std::vector<std::filesystem::path> inputs(a.maps.begin(), a.maps.end());
  inputs.emplace_back(a.mesh);
  if (!a.env.empty()) inputs.emplace_back(a.env);
  const int frames = std::max(1, a.camera.turntable);
  OutputPlan outputs(inputs);
  std::vector<std::string> frame_tmp;
  for (int k = 0; k < frames; ++k) frame_tmp.push_back(outputs.file(frame_path(a.output, a.camera.turntable, k)));
  const std::string json = outputs.file(a.json);

  const auto t_load = std::chrono::steady_clock::now();
  MeshLoadReport mesh_report;
  const Mesh mesh = load_mesh(a.mesh, &mesh_report);
  std::vector<MapSet> sets;
  sets.reserve(a.maps.size());
  long sanitized = 0;
  for (const std::string& m : a.maps) {
    long zeroed = 0;
    sets.push_back(read_map_set(m, a.sanitize ? BadTexels::zero : BadTexels::refuse, &zeroed));
    sanitized += zeroed;
    try {
      validate(sets.back());
    } catch (const std::exception& e) {
      throw std::invalid_argument(m + ": " + e.what());
    }
  }
  EnvMap env;
  if (!a.env.empty()) {
    env = read_environment_input(a.env, "", a.sanitize);
    options.environment = &env;
  }
  std::vector<const MapSet*> set_ptrs;
  for (const MapSet& s : sets) set_ptrs.push_back(&s);
  // Camera errors (bad --size etc.) before the scene is built.
  make_camera(a.camera, mesh.bounds(), 0);
  const Renderer renderer(mesh, set_ptrs, options);
  const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();

  std::map<std::string, std::string> provenance;
  provenance["version"] = RSIBR_VERSION;
  provenance["mode"] = to_string(options.mode);
  std::string maps_names;
  for (const std::string& m : a.maps) maps_names += (maps_names.empty() ? "" : " ") + file_name(m);
  provenance["maps"] = maps_names;
  provenance["mesh"] = file_name(a.mesh);
  provenance["spp"] = std::to_string(a.spp);
  provenance["lod"] = a.lod ? "footprint" : "point";
  if (options.mode == RenderMode::Paper) {
    provenance["warp"] = a.warp;
    provenance["mapSize"] = std::to_string(a.map_size > 0 ? a.map_size : sets.front().width());
  }
  if (!a.env.empty()) provenance["environment"] = file_name(a.env);

  Progress bar("render", !a.quiet && frames > 1 && Progress::stderr_is_terminal());
  nlohmann::json jframes = nlohmann::json::array();
  double render_total = 0;
  long long hits_total = 0;
  std::optional<float> stops = a.exposure;
  cv::Mat image;  // one frame buffer for every frame of a turntable
  for (int k = 0; k < frames; ++k) {
    const Camera cam = make_camera(a.camera, mesh.bounds(), k);
    RenderStats stats;
    renderer.render(cam, image, &stats);
    render_total += stats.seconds;
    hits_total += stats.hits;
    const std::string path = frame_path(a.output, a.camera.turntable, k);
    auto p = provenance;
    if (a.camera.turntable > 0) p["frame"] = std::to_string(k) + "/" + std::to_string(a.camera.turntable);
    if (ext == ".exr")
      write_render_exr(frame_tmp[std::size_t(k)], image, cam, p);
    else {
      if (!stops) stops = preview_exposure(image);  // every frame of a turntable at one exposure
      write_rgba_png(frame_tmp[std::size_t(k)], image, *stops);
    }
    jframes.push_back({{"path", path},
                       {"seconds", stats.seconds},
                       {"seconds_blend", stats.seconds_blend},
                       {"samples", stats.samples},
                       {"hits", stats.hits},
                       {"covered_pixels", stats.covered_pixels}});
    bar.update(double(k + 1) / frames);
  }
  bar.done();

  nlohmann::json j;
  j["maps"] = a.maps;
  j["mesh"] = a.mesh;
  j["mesh_triangles"] = mesh_report.triangles;
  j["mode"] = to_string(options.mode);
  if (options.mode == RenderMode::Paper) {
    j["warp"] = a.warp;
    j["map_size"] = a.map_size > 0 ? a.map_size : sets.front().width();
  }
  j["spp"] = a.spp;
  j["lod"] = a.lod;
  j["size"] = a.camera.size;
  j["frames"] = jframes;
  j["load_seconds"] = load_seconds;
  j["render_seconds_per_frame"] = render_total / frames;
  j["fps"] = render_total > 0 ? frames / render_total : 0.0;
  j["hits"] = hits_total;
  j["values_sanitized"] = sanitized;
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_render(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* c = app.add_subcommand("render", "Render a mesh (.glb, .gltf, .obj) with one or more map sets");
  c->footer(
      "Primary rays (Embree, one per pixel centre, mrcal pixel convention; --spp for a k x k subpixel grid) find "
      "the visible surface; its shading normal and the direction to the eye index the map sets.\n"
      "Modes: per-pixel (default, exact: every pixel blends the located sources for its own view direction) or "
      "paper (one destination map per frame for the camera's central direction, read by normal: error grows "
      "with the field of view).\n"
      "Several --maps are summed (e.g. a normal-lobe and a mirror-lobe set of one BRDF), each with its own warp.\n"
      "Output: .exr (RGBA float32, premultiplied, camera in the header) or .png (OpenColorIO display transform, "
      "$OCIO honoured; straight alpha). Misses are black with alpha 0 unless --env is given.\n"
      "Example: rsibr render --maps maps.exr --mesh cache/assets/models/bunny.glb bunny.png --turntable 36");
  c->add_option("--maps", a->maps, "Map set (.exr); repeat to sum several sets")->required();
  c->add_option("--mesh", a->mesh, "Mesh (.glb, .gltf, .obj)")->required();
  c->add_option("output,--out", a->output, "Output image (.png or .exr); numbered with --turntable")->required();
  add_camera_options(c, a->camera);
  c->add_option("--mode", a->mode, "per-pixel (exact) or paper (one destination map per frame)")->capture_default_str();
  c->add_option("--size-map", a->map_size, "paper: destination map size (default: the first map set's)")
      ->check(CLI::Range(2, 8192));
  c->add_option(
       "--warp", a->warp,
       "paper: exact, precomputed, tessellated or double-indirection (about world up) warp for the destination map")
      ->capture_default_str();
  c->add_option("--rings", a->rings, "tessellated: rings of the disc mesh (4x as many segments)")
      ->check(CLI::Range(1, 1024));
  c->add_option("--rim-fade", a->rim_fade, "Width of the singularity fade (0 disables)")->check(CLI::Range(0.0, 1.0));
  c->add_option("--spp", a->spp, "Samples per pixel: a perfect square (1, 4, 9, ...)")->check(CLI::Range(1, 1024));
  c->add_flag("--lod", a->lod,
              "read the maps at each pixel's level of detail (ray differentials, MIP levels of the sources in "
              "per-pixel mode, of the destination map in paper mode; for sets of mixed resolution the MIP-mask "
              "blend): no scintillation on small or distant objects");
  c->add_option("--env", a->env, "Environment map shown where rays miss (alpha 1)");
  c->add_option(
      "--exposure", a->exposure,
      "PNG: exposure in stops before the display transform (default: the first frame's median luminance at mid-grey)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
              "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar");
  return [a] { return run_render(*a); };
}

}  // namespace rsibr::cli
