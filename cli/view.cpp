// rsibr view: the interactive viewer (runtime/viewer/viewer.h), or its scripted mode (--orbit N):
// a turntable drawn with OpenGL without interaction, for screenshots (--screenshot, --exr), frame
// times (--benchmark) and the CI test under Xvfb. Built without the viewer (RSIBR_BUILD_VIEWER off,
// or GLFW/OpenGL/libepoxy/Dear ImGui missing), the verb says so and exits non-zero.
#include "cli/camera_options.h"
#include "cli/render_image.h"
#include "cli/rgba_png.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "formats/output_plan.h"
#include "core/progress.h"
#include "core/text.h"
#include "runtime/make_warp.h"
#include "runtime/renderer.h"
#include "runtime/web_viewer_page.h"
#include "core/sphere_mesh.h"
#if RSIBR_HAVE_VIEWER
#include "runtime/viewer/viewer.h"
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>

namespace rsibr::cli {
namespace {

struct ViewArgs {
  std::string maps, maps2, mesh, mode = "per-pixel", warp = "precomputed", compare = "wipe", display, view;
  std::string screenshot, exr, json, html;
  CameraArgs camera;
  int map_size = 0, rings = 16, orbit = 0;
  double rim_fade = 0.4, wipe = 0.5;
  float exposure = 0.f;
  bool weights = false, benchmark = false, quiet = false, sanitize = false;
};

MapSet load_maps(const std::string& path, bool sanitize) {
  MapSet set = read_map_set(path, sanitize ? BadTexels::zero : BadTexels::refuse);
  try {
    validate(set);
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  return set;
}

// --html: the page viewer (runtime/web_viewer_page.h), no OpenGL here.
int run_view_html(const ViewArgs& a) {
  if (a.mode != "per-pixel") throw std::invalid_argument("--html: the page draws per pixel (no --mode paper)");
  if (a.orbit > 0 || !a.screenshot.empty() || !a.exr.empty() || a.benchmark || a.weights)
    throw std::invalid_argument("--html writes a page: no --orbit, --screenshot, --exr, --benchmark or --weights");
  if (std::filesystem::path(a.html).extension() != ".html")
    throw std::invalid_argument(a.html + ": --html must be a .html file");
  std::vector<std::filesystem::path> inputs{a.maps};
  if (!a.maps2.empty()) inputs.emplace_back(a.maps2);
  if (!a.mesh.empty()) inputs.emplace_back(a.mesh);
  OutputPlan outputs(inputs);
  const std::string tmp = outputs.file(a.html);
  const std::string json = outputs.file(a.json);
  const MapSet set = load_maps(a.maps, a.sanitize);
  std::optional<MapSet> set2;
  if (!a.maps2.empty()) set2 = load_maps(a.maps2, a.sanitize);
  // Without a mesh: the ball, a unit sphere.
  const Mesh mesh = a.mesh.empty() ? sphere_mesh(Eigen::Vector3f::Zero(), 1.f) : load_mesh(a.mesh);
  WebViewerPage page;
  page.maps = &set;
  page.maps2 = set2 ? &*set2 : nullptr;
  page.names[0] = file_name(a.maps);
  page.names[1] = a.maps2.empty() ? "" : file_name(a.maps2);
  page.mesh = &mesh;
  page.blend.rim_fade = a.rim_fade;
  page.camera = make_camera(a.camera, mesh.bounds(), 0);
  page.pivot = a.camera.at.empty() ? Vec3(mesh.bounds().center().cast<double>()) : parse_vec3(a.camera.at, "--at");
  page.up = parse_vec3(a.camera.up, "--up");
  page.exposure = a.exposure;
  page.display = a.display;
  page.display_view = a.view;
  page.title = "rsibr view: " + file_name(a.maps) + (a.maps2.empty() ? "" : " | " + file_name(a.maps2)) +
               (a.mesh.empty() ? "" : " on " + file_name(a.mesh));
  std::string html;
  try {
    html = web_viewer_page(page);
  } catch (const std::invalid_argument& e) {  // what the shader cannot draw: name the sets
    throw std::invalid_argument(a.maps + (a.maps2.empty() ? "" : " / " + a.maps2) + ": " + e.what());
  }
  {
    std::ofstream out(tmp, std::ios::binary);
    out << html;
    if (!out.flush()) throw std::runtime_error(a.html + ": cannot write");
  }
  nlohmann::json j;
  j["html"] = a.html;
  j["bytes"] = html.size();
  j["maps"] = a.maps;
  j["mesh"] = a.mesh.empty() ? nlohmann::json("sphere") : nlohmann::json(a.mesh);
  j["size"] = {page.camera.width, page.camera.height};
  write_summary(json, j);
  outputs.commit();
  return 0;
}

int run_view(const ViewArgs& a) {
  if (!a.html.empty()) return run_view_html(a);
  if (a.mesh.empty()) throw std::invalid_argument("--mesh is required (without --html)");
  if (a.mode != "paper" && a.mode != "per-pixel")
    throw std::invalid_argument("--mode must be 'paper' or 'per-pixel', not '" + a.mode + "'");
  if (!is_warp_name(a.warp))
    throw std::invalid_argument(std::string("--warp must be ") + warp_names() + ", not '" + a.warp + "'");
  if (a.compare != "wipe" && a.compare != "side")
    throw std::invalid_argument("--compare must be 'wipe' or 'side', not '" + a.compare + "'");
  const bool scripted = a.orbit > 0;
  if (!scripted && (!a.screenshot.empty() || !a.exr.empty() || a.benchmark))
    throw std::invalid_argument("--screenshot, --exr and --benchmark need scripted mode (--orbit N)");
  if (!a.screenshot.empty() && std::filesystem::path(a.screenshot).extension() != ".png")
    throw std::invalid_argument(a.screenshot + ": --screenshot must be a .png file");
  if (!a.exr.empty() && std::filesystem::path(a.exr).extension() != ".exr")
    throw std::invalid_argument(a.exr + ": --exr must be a .exr file");
#if !RSIBR_HAVE_VIEWER
  throw std::runtime_error(
      "this rsibr was built without the viewer (configure with -DRSIBR_BUILD_VIEWER=ON and GLFW, OpenGL, "
      "libepoxy and Dear ImGui installed: scripts/install-deps.sh)");
#else
  // Every output is checked before any work (numbered like rsibr render --turntable N).
  std::vector<std::filesystem::path> inputs{a.maps, a.mesh};
  if (!a.maps2.empty()) inputs.emplace_back(a.maps2);
  OutputPlan outputs(inputs);
  std::vector<std::string> png_tmp, exr_tmp;
  for (int k = 0; k < std::max(1, a.orbit); ++k) {
    if (!a.screenshot.empty()) png_tmp.push_back(outputs.file(frame_path(a.screenshot, a.orbit, k)));
    if (!a.exr.empty()) exr_tmp.push_back(outputs.file(frame_path(a.exr, a.orbit, k)));
  }
  const std::string json = outputs.file(a.json);

  MeshLoadReport mesh_report;
  const Mesh mesh = load_mesh(a.mesh, &mesh_report);
  std::vector<MapSet> sets;
  sets.reserve(2);
  sets.push_back(load_maps(a.maps, a.sanitize));
  if (!a.maps2.empty()) sets.push_back(load_maps(a.maps2, a.sanitize));

  viewer::ViewerScene scene;
  scene.mesh = &mesh;
  for (const MapSet& s : sets) scene.sets.push_back(&s);
  scene.names.push_back(file_name(a.maps));
  if (!a.maps2.empty()) scene.names.push_back(file_name(a.maps2));

  viewer::ViewerSettings st;
  st.mode = render_mode_from_string(a.mode);
  st.warp = a.warp;
  st.map_size = a.map_size;
  st.rings = a.rings;
  st.blend.rim_fade = a.rim_fade;
  st.exposure = a.exposure;
  st.display = a.display;
  st.view = a.view;
  st.compare = a.compare == "side" ? viewer::Compare::SideBySide : viewer::Compare::Wipe;
  st.wipe = float(std::clamp(a.wipe, 0.0, 1.0));
  st.show_weight = a.weights;
  CameraArgs first = a.camera;
  first.turntable = 0;
  st.camera = make_camera(first, mesh.bounds(), 0);
  st.pivot = a.camera.at.empty() ? Vec3(mesh.bounds().center().cast<double>()) : parse_vec3(a.camera.at, "--at");
  st.up = parse_vec3(a.camera.up, "--up");
  st.vfov_deg = a.camera.fov;

  if (!scripted) return viewer::run_interactive(scene, st);

  std::map<std::string, std::string> provenance;
  provenance["version"] = RSIBR_VERSION;
  provenance["mode"] = a.mode;
  provenance["maps"] = file_name(a.maps) + (a.maps2.empty() ? "" : " " + file_name(a.maps2));
  provenance["mesh"] = file_name(a.mesh);
  provenance["renderer"] = "rsibr view (OpenGL)";
  if (st.mode == RenderMode::Paper) provenance["warp"] = a.warp;

  Progress bar("view", !a.quiet && !a.benchmark && a.orbit > 1 && Progress::stderr_is_terminal());
  nlohmann::json jframes = nlohmann::json::array();
  std::vector<double> times;
  std::string gl_renderer;
  const bool read_back = !a.screenshot.empty() || !a.exr.empty();
  viewer::run_scripted(
      scene, st, a.orbit, read_back,
      [&](const viewer::ScriptedFrame& f) {
        times.push_back(f.seconds);
        nlohmann::json jf{{"index", f.index}, {"seconds", f.seconds}, {"seconds_blend", f.seconds_blend}};
        auto p = provenance;
        p["frame"] = std::to_string(f.index) + "/" + std::to_string(a.orbit);
        if (!a.screenshot.empty()) {
          const std::string path = frame_path(a.screenshot, a.orbit, f.index);
          write_rgba_png(png_tmp.at(std::size_t(f.index)), f.rgba, a.exposure, a.display, a.view);
          jf["screenshot"] = path;
        }
        if (!a.exr.empty()) {
          const std::string path = frame_path(a.exr, a.orbit, f.index);
          write_render_exr(exr_tmp.at(std::size_t(f.index)), f.rgba, f.camera, p);
          jf["exr"] = path;
        }
        if (a.benchmark) std::printf("frame %d %.3f ms\n", f.index, 1e3 * f.seconds);
        jframes.push_back(jf);
        bar.update(double(f.index + 1) / a.orbit);
      },
      &gl_renderer);
  bar.done();
  // The first frame includes shader compilation and first-use costs: the steady rate excludes it.
  std::vector<double> steady(times.begin() + (times.size() > 1 ? 1 : 0), times.end());
  std::sort(steady.begin(), steady.end());
  const double median = steady[steady.size() / 2];
  double total = 0;
  for (double t : steady) total += t;
  if (a.benchmark)
    std::printf("%s: %d frames %dx%d, median %.3f ms (%.1f fps), mean %.3f ms; %s\n", a.mode.c_str(), a.orbit,
                st.camera.width, st.camera.height, 1e3 * median, 1.0 / median, 1e3 * total / double(steady.size()),
                gl_renderer.c_str());
  nlohmann::json j;
  j["maps"] = a.maps2.empty() ? nlohmann::json{a.maps} : nlohmann::json{a.maps, a.maps2};
  j["mesh"] = a.mesh;
  j["mesh_triangles"] = mesh_report.triangles;
  j["mode"] = a.mode;
  j["size"] = a.camera.size;
  j["gl_renderer"] = gl_renderer;
  j["frames"] = jframes;
  j["median_frame_seconds"] = median;
  j["fps"] = median > 0 ? 1.0 / median : 0.0;
  write_summary(json, j);
  outputs.commit();
  return 0;
#endif
}

}  // namespace

Runner add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* c = app.add_subcommand("view", "Interactive viewer: orbit a mesh lit by one or two map sets (OpenGL)");
  std::string footer =
      "A GLFW window (OpenGL 3.3 core) with a Dear ImGui panel. Each frame the mesh is drawn with the map set: per "
      "pixel in a fragment shader implementing the runtime's formulas (default), or --mode paper: the CPU engine "
      "blends one destination map per frame, read by normal. Two sets (--maps2) are compared by a wipe or side by "
      "side. Colours: exposure and the OpenColorIO display transform ($OCIO honoured).\n"
#if RSIBR_HAVE_VIEWER
      "Keys: " +
      std::string(viewer::kViewerKeys) +
      "\n"
#else
      "(This rsibr was built without the viewer.)\n"
#endif
      "Scripted mode (--orbit N): no interaction; N turntable frames (the frames of rsibr render --turntable N), "
      "--screenshot (PNG, as rsibr render's) and --exr (RGBA float) numbered like rsibr render's, --benchmark "
      "prints frame times. Needs a display: use `xvfb-run -a rsibr view ...` on a machine without one.\n"
      "--html OUT.html writes the viewer as one self-contained web page (WebGL2, per pixel, the same shader; with "
      "--maps2 a wipe; no display needed) and exits.\n"
      "Example: rsibr view --maps maps.exr --mesh cache/assets/models/bunny.glb";
  c->footer(footer);
  c->add_option("--maps", a->maps, "Map set (.exr)")->required();
  c->add_option("--maps2", a->maps2, "A second map set to compare (wipe or side by side)");
  c->add_option("--mesh", a->mesh, "Mesh (.glb, .gltf, .obj); with --html optional (default: a sphere, the ball)");
  c->add_option("--html", a->html,
                "Write a self-contained web page (WebGL2) of the mesh lit by --maps, per pixel, and exit (no "
                "display needed)");
  add_camera_options(c, a->camera);
  c->remove_option(c->get_option("--turntable"));  // --orbit here
  c->add_option("--mode", a->mode, "per-pixel (fragment shader) or paper (CPU destination map)")->capture_default_str();
  c->add_option("--warp", a->warp, "paper: exact, precomputed, tessellated or double-indirection (about world up) warp")
      ->capture_default_str();
  c->add_option("--size-map", a->map_size, "paper: destination map size (default: the set's)")
      ->check(CLI::Range(2, 8192));
  c->add_option("--rings", a->rings, "tessellated: rings of the disc mesh")->check(CLI::Range(1, 1024));
  c->add_option("--rim-fade", a->rim_fade, "Width of the singularity fade (0 disables)")->check(CLI::Range(0.0, 1.0));
  c->add_option("--exposure", a->exposure, "Exposure in stops before the display transform");
  c->add_option("--display", a->display, "OpenColorIO display (default: the config's)");
  c->add_option("--display-view", a->view, "OpenColorIO view of the display (default: the display's)");
  c->add_option("--compare", a->compare, "Two sets: wipe or side")->capture_default_str();
  c->add_option("--wipe", a->wipe, "Wipe position: fraction of the width showing --maps")->check(CLI::Range(0.0, 1.0));
  c->add_flag("--weights", a->weights, "Show the sum of the faded weights (singularity fades) instead of radiance");
  c->add_option("--orbit", a->orbit, "Scripted mode: N turntable frames about --up through --at, no interaction")
      ->check(CLI::Range(1, 100000));
  c->add_option("--screenshot", a->screenshot, "Scripted: write each frame as PNG (numbered when N > 1)");
  c->add_option("--exr", a->exr, "Scripted: write each frame as RGBA float EXR (numbered when N > 1)");
  c->add_flag("--benchmark", a->benchmark, "Scripted: print each frame's time and the median frame rate");
  c->add_option("--json", a->json, "Scripted: write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
              "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar");
  return [a] { return run_view(*a); };
}

}  // namespace rsibr::cli
