#include "pipeline/render_step.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "core/camera.h"
#include "core/colour.h"
#include "core/mesh.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/resample.h"
#include "core/view_set.h"
#include "formats/atomic_folder.h"
#include "formats/exr_io.h"
#include "formats/image_codecs.h"
#include "formats/map_set.h"
#include "pipeline/torus_mesh.h"
#include "runtime/renderer.h"
#include "runtime/web_viewer_page.h"

#include <iomanip>
#include <optional>
#include <sstream>

namespace rsibr {

StepOutputs run_render_step(const RenderStep& s) {
  StepOutputs out;
  const EnvMap probe = read_environment(s.probe.string());
  const auto brdf = parse_brdf(s.brdf);
  // The render's maps are views_res texels of a glossy lobe: a probe wider than 512 adds nothing to
  // them but the integrator's MIP pyramid (7 s of 9 for a 1472-wide probe on 2 cores). Area
  // sampling keeps the energy; the full probe stays the background.
  std::optional<EnvMap> smaller;
  if (probe.layout.width() > 512) {
    ResampleOptions rs;
    rs.supersampling = 1;
    smaller = resample(probe, Layout(LayoutKind::LatLong, 512, 256), rs);
  }
  const auto integrator = make_integrator("fis", smaller ? *smaller : probe);
  MapSetBakeOptions bo;
  bo.res = s.views_res;
  bo.integrator.samples = 32;
  bo.integrator.seed = s.seed;
  bo.environment_name = s.probe.filename().string();
  const MapSet maps = bake_map_set(*brdf, *integrator, ViewSet::named("icosa"), bo);
  std::filesystem::create_directories(s.out);
  write_map_set((s.out / "maps.exr").string(), maps);
  const Mesh mesh = s.mesh.empty() ? torus_mesh() : load_mesh(s.mesh);
  RenderOptions ro;
  ro.environment = &probe;
  const Renderer renderer(mesh, {&maps}, ro);
  const Eigen::AlignedBox3f box = mesh.bounds();
  const Vec3 pivot = box.center().cast<double>();
  const Camera first = frame_bounds(box, Vec3(0, -0.4, -1), Vec3(0, 1, 0), 40, s.width, s.height);
  // Display exposure: the probe's median at mid-grey (the object reflects the environment).
  const float stops = preview_exposure(probe.pixels);
  FolderContents files;
  double seconds = 0;
  Progress bar("render", s.progress);
  for (int k = 0; k < s.frames; ++k) {
    RenderStats stats;
    const cv::Mat rgba = renderer.render(orbit(first, pivot, Vec3(0, 1, 0), k, s.frames), &stats);
    seconds += stats.seconds;
    std::ostringstream name;
    name << "frame_" << std::setw(2) << std::setfill('0') << k << ".png";
    files[name.str()] = png_bytes(display_encode(rgba, stops), name.str());
    bar.update(double(k + 1) / s.frames);
  }
  bar.done();
  // The same turntable to orbit in a browser: the first frame's camera, the same exposure (no
  // background: the page draws the object).
  WebViewerPage page;
  page.maps = &maps;
  page.mesh = &mesh;
  page.camera = first;
  page.pivot = pivot;
  page.exposure = stops;
  page.title = "rsibr: " + brdf->spec() + " on " +
               (s.mesh.empty() ? std::string("a torus") : std::filesystem::path(s.mesh).filename().string());
  const std::string html = web_viewer_page(page);
  files["viewer.html"] = std::vector<unsigned char>(html.begin(), html.end());
  write_folder_atomically(s.out, files);
  out.files.push_back(s.out / "maps.exr");
  for (const auto& [name, bytes] : files) out.files.push_back(s.out / name);
  out.summary = {{"mesh", s.mesh.empty() ? "built-in torus" : s.mesh},
                 {"triangles", mesh.triangles.size()},
                 {"material", brdf->spec()},
                 {"frames", s.frames},
                 {"seconds_per_frame", seconds / s.frames},
                 {"display_exposure_stops", stops},
                 {"size", {s.width, s.height}},
                 {"viewer", "viewer.html"},
                 {"viewer_bytes", html.size()}};
  return out;
}

}  // namespace rsibr
