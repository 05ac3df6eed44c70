// rsibr reference: the ground-truth render of a mesh with a BRDF under an environment, seen by a
// perspective camera (bake/reference_renderer.h for what a pixel holds).
#include "cli/camera_options.h"
#include "formats/file_error.h"
#include "cli/option_checks.h"
#include "cli/render_image.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "bake/brdf_spec.h"
#include "bake/reference_renderer.h"
#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/exr_io.h"
#include "core/mesh.h"
#include "formats/output_plan.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/ray_scene.h"

#include "formats/image_codecs.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace rsibr::cli {
namespace {

struct ReferenceArgs {
  std::string mesh, env, brdf, output, preview, json, background = "env", layout;
  CameraArgs camera;
  int spp = 64, light_samples = 1, bounces = 1;
  std::uint64_t seed = 0;
  bool shadows = true, sanitize = false, quiet = false;
  std::optional<float> preview_exposure;  // nullopt: metered on the first frame (core/preview_exposure.h)
};

// RGBA float32 (RGB radiance, A coverage) with the render's provenance.
void write_render(const std::string& path, const ReferenceImage& im, const Camera& cam,
                  const std::map<std::string, std::string>& strings, const ReferenceOptions& o) {
  cv::Mat rgba(im.rgb.rows, im.rgb.cols, CV_32FC4);
  const int from_to[] = {0, 0, 1, 1, 2, 2, 3, 3};
  const cv::Mat sources[] = {im.rgb, im.alpha};
  cv::mixChannels(sources, 2, &rgba, 1, from_to, 4);
  std::map<std::string, std::string> all = strings;
  all["seed"] = std::to_string(o.seed);
  all["background"] = to_string(o.background);
  write_render_exr(path, rgba, cam, all,
                   {{"spp", o.spp},
                    {"lightSamples", o.light_samples},
                    {"shadows", o.shadows ? 1 : 0},
                    {"bounces", o.shadows ? o.bounces : 1}});
}

int run_reference(const ReferenceArgs& a) {
  if (std::filesystem::path(a.output).extension() != ".exr")
    throw std::invalid_argument(a.output + ": the output must be an .exr file");
  const int frames = std::max(1, a.camera.turntable);
  OutputPlan outputs({a.mesh, a.env, a.brdf});
  std::vector<std::string> exr_tmp, png_tmp;
  for (int k = 0; k < frames; ++k) {
    exr_tmp.push_back(outputs.file(frame_path(a.output, a.camera.turntable, k)));
    if (!a.preview.empty()) png_tmp.push_back(outputs.file(frame_path(a.preview, a.camera.turntable, k)));
  }
  const std::string json = outputs.file(a.json);
  ReferenceOptions o;
  o.spp = a.spp;
  o.light_samples = a.light_samples;
  o.seed = a.seed;
  o.shadows = a.shadows;
  o.bounces = a.bounces;
  o.background = parse_background(a.background);

  const auto t0 = std::chrono::steady_clock::now();
  MeshLoadReport mesh_report;
  const Mesh mesh = load_mesh(a.mesh, &mesh_report);
  // Validate the camera options before the slower environment and scene set-up.
  const Camera first = make_camera(a.camera, mesh.bounds(), 0);
  const std::unique_ptr<Brdf> brdf = load_brdf(a.brdf);
  const EnvMap env = read_environment_input(a.env, a.layout, a.sanitize);
  const ReferenceLighting lighting(env);
  const auto t1 = std::chrono::steady_clock::now();
  const RayScene scene(mesh);
  const auto t2 = std::chrono::steady_clock::now();

  const std::map<std::string, std::string> strings = {{"version", RSIBR_VERSION},
                                                      {"mesh", a.mesh},
                                                      {"environment", a.env},
                                                      {"material", brdf->spec()},
                                                      {"brdfSpec", a.brdf}};
  Progress bar("reference", !a.quiet && Progress::stderr_is_terminal());
  double render_s = 0, write_s = 0;
  long samples = 0, hits = 0, shadow_rays = 0, bounce_rays = 0;
  nlohmann::json frames_json = nlohmann::json::array();
  std::optional<float> stops = a.preview_exposure;  // every frame of a turntable at one exposure
  for (int k = 0; k < frames; ++k) {
    const Camera cam = k == 0 ? first : make_camera(a.camera, mesh.bounds(), k);
    const auto r0 = std::chrono::steady_clock::now();
    const double rows_total = double(frames) * cam.height;
    const ReferenceImage im = render_reference(
        scene, *brdf, lighting, cam, o, [&](int done) { bar.update((double(k) * cam.height + done) / rows_total); });
    const auto r1 = std::chrono::steady_clock::now();
    const std::string out = frame_path(a.output, a.camera.turntable, k);
    write_render(exr_tmp[std::size_t(k)], im, cam, strings, o);
    if (!a.preview.empty() && !write_image(png_tmp[std::size_t(k)],
                                           display_encode(im.rgb, *(stops = stops ? stops : preview_exposure(im.rgb)))))
      throw FileError(frame_path(a.preview, a.camera.turntable, k), "cannot write the preview image", {},
                      FileRole::Output);
    const auto r2 = std::chrono::steady_clock::now();
    render_s += std::chrono::duration<double>(r1 - r0).count();
    write_s += std::chrono::duration<double>(r2 - r1).count();
    samples += im.samples;
    hits += im.hits;
    shadow_rays += im.shadow_rays;
    bounce_rays += im.bounce_rays;
    frames_json.push_back({{"output", out},
                           {"eye", {cam.eye.x(), cam.eye.y(), cam.eye.z()}},
                           {"coverage", cv::mean(im.alpha)[0]},
                           {"seconds", std::chrono::duration<double>(r1 - r0).count()}});
  }
  bar.done();

  auto secs = [](auto d) { return std::chrono::duration<double>(d).count(); };
  if (!a.quiet)
    std::cerr << "rsibr reference: " << frames << (frames == 1 ? " frame " : " frames ") << first.width << "x"
              << first.height << ", " << a.spp << " spp, shadows " << (o.shadows ? "on" : "off") << ", "
              << (o.shadows ? o.bounces : 1) << (o.shadows && o.bounces > 1 ? " bounces" : " bounce") << ", "
              << render_s << " s (" << double(hits) / double(std::max(1L, samples)) * 100 << "% of samples hit)\n";
  nlohmann::json j;
  j["output"] = a.output;
  j["frames"] = frames_json;
  j["mesh"] = a.mesh;
  j["mesh_vertices"] = mesh_report.vertices;
  j["mesh_triangles"] = mesh_report.triangles;
  j["environment"] = a.env;
  j["environment_layout"] = to_string(env.layout.kind());
  j["environment_size"] = {env.layout.width(), env.layout.height()};
  j["material"] = brdf->spec();
  j["size"] = {first.width, first.height};
  j["intrinsics"] = {{"fx", first.fx}, {"fy", first.fy}, {"cx", first.cx}, {"cy", first.cy}};
  j["spp"] = a.spp;
  j["light_samples"] = a.light_samples;
  j["seed"] = a.seed;
  j["shadows"] = o.shadows;
  j["bounces"] = o.shadows ? o.bounces : 1;
  j["background"] = to_string(o.background);
  j["samples"] = samples;
  j["hits"] = hits;
  j["shadow_rays"] = shadow_rays;
  j["bounce_rays"] = bounce_rays;
  j["seconds"] = {{"load", secs(t1 - t0)}, {"scene", secs(t2 - t1)}, {"render", render_s}, {"write", write_s}};
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_reference(CLI::App& app) {
  auto a = std::make_shared<ReferenceArgs>();
  CLI::App* c = app.add_subcommand(
      "reference", "Ground-truth render of a mesh with a BRDF under an environment (Embree path tracing)");
  c->footer(
      "Each pixel is the mean of --spp camera samples. A hit reflects the environment through the BRDF with the "
      "interpolated shading normal; lighting combines environment and BRDF sampling (MIS). --no-shadows gives the "
      "baked-map contract that runtime renders must match: no occlusion, no bounces. --shadows (the default) makes "
      "the mesh opaque: it shadows itself and, with --bounces N > 1, lights itself (N surface interactions per "
      "path). Output: RGBA float32 EXR, A = coverage, with the camera and settings in rsibr.* attributes. The same "
      "inputs and --seed give the same bytes.\n"
      "Example: rsibr reference --mesh bunny.glb --env lobby.exr --brdf gold.yaml --size 640x360 --spp 64 "
      "--preview bunny.png bunny.exr");
  c->add_option("output", a->output, "Output image (.exr; numbered with --turntable)")->required();
  c->add_option("--mesh", a->mesh, "Mesh (.obj, .gltf, .glb)")->required();
  c->add_option("--env", a->env, "Environment map (EXR or .hdr), any layout")->required();
  c->add_option("--brdf", a->brdf, "BRDF spec (YAML)")->required();
  add_camera_options(c, a->camera);
  c->add_option("--spp", a->spp, "Camera samples per pixel (stratified)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 16));
  c->add_option("--light-samples", a->light_samples, "Environment and BRDF samples per surface interaction (each)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 12));
  c->add_option("--seed", a->seed, "Random seed")->capture_default_str()->check(seed_check());
  c->add_flag("--shadows,!--no-shadows", a->shadows,
              "Self-shadowing (default on); --no-shadows: the baked-map contract (no occlusion, no bounces)");
  c->add_option("--bounces", a->bounces, "Surface interactions per path, with shadows (1: direct light only)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  c->add_option("--background", a->background, "What misses show: env (the environment) or black")
      ->capture_default_str()
      ->check(CLI::IsMember({"env", "black"}));
  c->add_option("--layout", a->layout, "Layout of the environment when its header and shape do not tell");
  c->add_flag(
      "--sanitize", a->sanitize,
      "Zero NaN, Inf and absurd environment values instead of failing (negative values are always folded into their positive neighbours, energy kept)");
  c->add_option("--preview", a->preview, "Also write a display-encoded PNG (OCIO; numbered with --turntable)");
  c->add_option("--preview-exposure", a->preview_exposure,
                "Exposure of the preview in stops (default: the first frame's median luminance at mid-grey)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or summary line");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] { return run_reference(*a); };
}

}  // namespace rsibr::cli
