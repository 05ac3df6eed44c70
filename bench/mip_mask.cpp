// MIP-mask blending measured (runtime/blend_engine.h, core/resolution_mask.h):
//   scintillation: a small, distant mesh in a slow turntable, rendered in per-pixel mode with one
//     bilinear tap per source and with lookups at each pixel's level of detail (--lod), against a
//     supersampled reference (spp 64, one tap): the frame-to-frame change that the reference does not
//     have, and each frame's error;
//   mixed resolution: a map set whose views were measured at two resolutions (every other view's
//     detail only 1/8 of the map size, as a ball 8 times smaller in its photo), blended to novel views
//     and assembled into a probe, with and without the native sizes that turn the MIP-mask blend on,
//     against the same set at full resolution.
// bench/mip_mask.py runs it and writes the docs/tradeoffs.md section "MIP-mask blending". Output:
// one JSON object on stdout.
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "calib/probe/probe.h"
#include "core/camera.h"
#include "formats/exr_io.h"
#include "core/mesh.h"
#include "core/resample.h"
#include "core/stopwatch.h"
#include "core/texel_audit.h"
#include "runtime/blend_engine.h"
#include "runtime/renderer.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <iostream>

using namespace rsibr;

namespace {

// RMS over the pixels covered in `ref` (alpha > 0.5) of an RGB difference image, and of ref itself.
double rms_rgb(const cv::Mat& diff, const cv::Mat& ref) {
  double s = 0;
  long n = 0;
  for (int r = 0; r < ref.rows; ++r)
    for (int c = 0; c < ref.cols; ++c) {
      if (ref.at<cv::Vec4f>(r, c)[3] < 0.5f) continue;
      const cv::Vec4f d = diff.at<cv::Vec4f>(r, c);
      s += double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2];
      ++n;
    }
  return n ? std::sqrt(s / n) : 0.0;
}

struct Turntable {
  std::vector<cv::Mat> frames;
  double seconds = 0;
};

Turntable turntable(const Renderer& renderer, const Mesh& mesh, int frames, double step_deg, int size) {
  const Eigen::AlignedBox3f box = mesh.bounds();
  const Vec3 centre = box.center().cast<double>();
  const double radius = 0.5 * double(box.diagonal().norm());
  Turntable t;
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    const double a = f * step_deg * kPi / 180;
    // A distant camera: the mesh's bounding sphere spans about 1/6 of the frame.
    const Vec3 eye = centre + radius * 14.0 * Vec3(std::sin(a), 0.25, std::cos(a)).normalized();
    const Camera cam = look_at(eye, centre, Vec3(0, 1, 0), 25.0, size, size);
    t.frames.push_back(renderer.render(cam));
  }
  t.seconds = seconds_since(t0) / frames;
  return t;
}

// Downsamples every other view's map by `factor` and back (area, then bilinear): the detail a ball
// `factor` times smaller in its photo would hold; records that native size when `tag` is set.
MapSet two_resolutions(const MapSet& full, int factor, bool tag) {
  MapSet out = full;
  for (std::size_t i = 0; i < out.views.size(); i += 2) {
    MapView& v = out.views[i];
    const int w = v.rgb.cols, small = std::max(2, w / factor);
    cv::Mat down, up;
    cv::resize(v.rgb, down, cv::Size(small, small), 0, 0, cv::INTER_AREA);
    cv::resize(down, up, cv::Size(w, w), 0, 0, cv::INTER_LINEAR);
    v.rgb = up;
    if (tag) v.attributes["nativeSize"] = std::to_string(small);
  }
  return out;
}

double map_rel_rms(const cv::Mat& a, const cv::Mat& truth) {
  double num = 0, den = 0;
  for (int r = 0; r < truth.rows; ++r)
    for (int c = 0; c < truth.cols; ++c) {
      const cv::Vec3f d = a.at<cv::Vec3f>(r, c) - truth.at<cv::Vec3f>(r, c), t = truth.at<cv::Vec3f>(r, c);
      num += double(d.dot(d));
      den += double(t.dot(t));
    }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string env_path, mesh_path,
      brdf_spec = "{type: ggx, roughness: 0.03, fresnel: {type: schlick, f0: [0.95, 0.64, 0.54]}}";
  int res = 128, frames = 24, size = 256;
  double step = 0.5;
  CLI::App app("MIP-mask blending: scintillation and mixed-resolution sets");
  app.add_option("--env", env_path)->required();
  app.add_option("--mesh", mesh_path)->required();
  app.add_option("--brdf", brdf_spec);
  app.add_option("--res", res);
  app.add_option("--frames", frames);
  app.add_option("--size", size);
  app.add_option("--step", step);
  CLI11_PARSE(app, argc, argv);
  try {
    EnvMap env = read_environment(env_path);
    sanitize_texels(env.pixels);  // lossy-compression ringing: negatives to 0
    const auto brdf = parse_brdf(brdf_spec);
    const auto integrator = make_integrator("fis", env);
    MapSetBakeOptions bo;
    bo.res = res;
    bo.integrator.samples = 64;
    const ViewSet views = ViewSet::named("42");
    auto t0 = std::chrono::steady_clock::now();
    const MapSet set = bake_map_set(*brdf, *integrator, views, bo);
    nlohmann::json out;
    out["env"] = env_path;
    out["brdf"] = brdf->spec();
    out["res"] = res;
    out["bake_seconds"] = seconds_since(t0);

    // Scintillation.
    const Mesh mesh = load_mesh(mesh_path);
    RenderOptions ro;
    ro.mode = RenderMode::PerPixel;
    const Renderer point(mesh, {&set}, ro);
    ro.lod = true;
    const Renderer lod(mesh, {&set}, ro);
    ro.lod = false;
    ro.spp = 64;
    const Renderer reference(mesh, {&set}, ro);
    const Turntable tp = turntable(point, mesh, frames, step, size), tl = turntable(lod, mesh, frames, step, size),
                    tr = turntable(reference, mesh, frames, step, size);
    double flicker_p = 0, flicker_l = 0, change_r = 0, err_p = 0, err_l = 0, level = 0;
    for (int f = 0; f < frames; ++f) {
      err_p += rms_rgb(tp.frames[f] - tr.frames[f], tr.frames[f]);
      err_l += rms_rgb(tl.frames[f] - tr.frames[f], tr.frames[f]);
      level += rms_rgb(tr.frames[f], tr.frames[f]);
      if (f == 0) continue;
      const cv::Mat dr = tr.frames[f] - tr.frames[f - 1];
      change_r += rms_rgb(dr, tr.frames[f]);
      flicker_p += rms_rgb((tp.frames[f] - tp.frames[f - 1]) - dr, tr.frames[f]);
      flicker_l += rms_rgb((tl.frames[f] - tl.frames[f - 1]) - dr, tr.frames[f]);
    }
    const double pairs = frames - 1;
    out["scintillation"] = {
        {"frames", frames},
        {"step_deg", step},
        {"size", size},
        {"reference_rms", level / frames},
        {"reference_change", change_r / pairs},
        {"point", {{"flicker", flicker_p / pairs}, {"error", err_p / frames}, {"ms", 1e3 * tp.seconds}}},
        {"lod", {{"flicker", flicker_l / pairs}, {"error", err_l / frames}, {"ms", 1e3 * tl.seconds}}},
        {"reference_ms", 1e3 * tr.seconds}};

    // Mixed resolution: blends at novel views and probes, against the full-resolution set.
    const MapSet plain = two_resolutions(set, 8, false), tagged = two_resolutions(set, 8, true);
    const BlendEngine e_full(set, views), e_plain(plain, views), e_tagged(tagged, views);
    double b_plain = 0, b_tagged = 0;
    const std::vector<Vec3> novel = {Vec3(0.3, 0.5, 0.8),  Vec3(-0.7, 0.2, 0.4),   Vec3(0.1, -0.9, 0.3),
                                     Vec3(0.6, 0.6, -0.5), Vec3(-0.2, 0.1, -0.95), Vec3(0.9, -0.3, 0.1)};
    for (const Vec3& d : novel) {
      const cv::Mat truth = e_full.map(d, Vec3(0, 1, 0)).rgb;
      b_plain += map_rel_rms(e_plain.map(d, Vec3(0, 1, 0)).rgb, truth);
      b_tagged += map_rel_rms(e_tagged.map(d, Vec3(0, 1, 0)).rgb, truth);
    }
    // Probes: the set as captured chrome maps (confidence 1 inside the disc).
    auto captured = [](MapSet s) {
      for (MapView& v : s.views) {
        v.source = MapSource::Captured;
        v.confidence = cv::Mat(v.rgb.rows, v.rgb.cols, CV_32FC1, cv::Scalar(1));
      }
      return s;
    };
    ProbeOptions po;
    po.width = 4 * res;
    const Probe p_full = assemble_probe(captured(set), po), p_plain = assemble_probe(captured(plain), po),
                p_tagged = assemble_probe(captured(tagged), po);
    out["mixed"] = {{"factor", 8},
                    {"novel_views", novel.size()},
                    {"blend_plain", b_plain / novel.size()},
                    {"blend_mip_mask", b_tagged / novel.size()},
                    {"probe_plain", map_rel_rms(p_plain.env.pixels, p_full.env.pixels)},
                    {"probe_mip_mask", map_rel_rms(p_tagged.env.pixels, p_full.env.pixels)}};
    std::cout << out.dump(1) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rsibr_mip_mask: " << e.what() << "\n";
    return 1;
  }
}
