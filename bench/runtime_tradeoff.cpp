// Measured accuracy of the runtime: error against time of the warp-and-blend
// for novel views (warp method x view count x map resolution), and of rendering against the reference
// render (paper mode and per-pixel mode). Writes JSON that bench/runtime_tradeoff.py turns into
// docs/tradeoffs.md sections and docs/figures/ plots. Not Google Benchmark: each row is a few timed
// frames and one error measurement.
//
//   rsibr_runtime_tradeoff novel  --env E.exr --brdf "ggx 0.2" --sets 64:12,64:42 --cache DIR --out n.json
//   rsibr_runtime_tradeoff render --mesh bunny.glb --env E.exr --sets 64:12 --cache DIR --out r.json
//
// Baking. Map sets and direct bakes use the reference integrator (a deterministic quadrature over every
// texel) on the environment's MIP level at most --env-width wide (core/mip_pyramid.h, exact energy), so
// they carry no noise: the measured error is the runtime's alone. The MIS integrator's noise at the same
// texels is reported (and why it was not used: its noise is above the dense sets' blend error), as is the
// quadrature's bias against the full environment. Sets are cached in --cache (keyed by environment, its
// working width, BRDF, method, view count and size).
//
// Novel views. A fixed set of random novel views (seed 5, each at least --min-separation degrees from
// every view of the 162-view set, which contains the 42- and 12-view sets' directions) is baked directly
// (frame world_from_view_for(d, +Y) = blend()'s frame for up = +Y). Each warp (exact, precomputed,
// tessellated with 8/16/32 rings and 4 x rings segments) blends every novel view; over the texels with
// blend weight > 0:
//   rel_rms = sqrt(sum_texels,rgb (blend - direct)^2 / sum_texels,rgb direct^2)   (pooled over the views)
//   worst   = max_texel |blend - direct|_2 (RGB) / sqrt(sum_texels |direct|_2^2 / n_texels)
//             (the worst texel in units of the map's RMS radiance; same normalisation as rel_rms)
// and the same two over the texels at disc radius <= 0.9 only ("inner": away from the rim, where the
// mirror direction approaches -v and every source is faded).
// Time per frame: median of --reps passes over the novel views (one blend per view per pass, so the
// tessellated warp's per-frame vertex cache never serves a repeated frame).
// Floor: blend() at a source view against a direct bake there (0 for a deterministic bake).
//
// Rendering. The mesh is framed like `rsibr render`'s default (--from 0,0.3,1) at each field of view.
// Reference: render_reference on the same working environment with shadows OFF (runtime maps hold no
// occlusion), background black, the mean of --ref-seeds renders (seeds 1, 2, ...) of spp/seeds samples
// each, accumulated in two halves A (odd seeds) and B (even); its noise is rms(A - (A+B)/2) (relative). The runtime renders the same camera (pixel-aligned) with the cached map
// sets (RenderOptions, warp "precomputed", map_size = the set's size) at spp 16 (the pixel footprint,
// like the reference) for the error and at spp 1 for the time per frame (median of --reps frames). Error
// over pixels with alpha = 1 in the reference and the runtime render; rel_rms and worst as above.
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/reference_renderer.h"
#include "core/camera.h"
#include "bench/measure.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "core/mip_pyramid.h"
#include "core/mesh.h"
#include "core/ray_scene.h"
#include "core/sphere_map.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/renderer.h"
#include "runtime/tessellated_warp.h"
#include "runtime/warp.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>

namespace rsibr {
namespace {

using namespace rsibr::bench;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string e; std::getline(ss, e, ',');)
    if (!e.empty()) out.push_back(e);
  return out;
}

// The BRDFs by short name (the conductor is gold's, as in bench/bake_tradeoff.cpp).
std::string brdf_spec(const std::string& name) {
  const std::string gold = "fresnel: {type: conductor, eta: [0.2, 0.92, 1.1], k: [3.9, 2.45, 2.14]}";
  if (name == "lambert") return "{type: lambert, albedo: [0.8, 0.8, 0.8]}";
  if (name == "ggx 0.2") return "{type: ggx, roughness: 0.2, " + gold + "}";
  if (name == "ggx 0.05") return "{type: ggx, roughness: 0.05, " + gold + "}";
  throw std::invalid_argument("unknown BRDF name '" + name + "' (lambert, ggx 0.2, ggx 0.05)");
}

std::string file_key(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

std::string view_set_name(int count) {
  if (count == 12) return "icosa";
  if (count == 42 || count == 162 || count == 642) return std::to_string(count);
  throw std::invalid_argument("view count must be 12, 42, 162 or 642");
}

// The environment the maps and the references integrate: the finest MIP level of the sanitized file
// whose width is at most max_width (core/mip_pyramid.h: exact energy; a 512-wide lat-long gives widths
// 513, 257, 129, 65, 33, ...), so that the deterministic quadrature of the reference integrator over
// every texel of it is affordable. 0 = the file as it is.
EnvMap working_environment(const std::string& path, int max_width) {
  EnvMap env = load_sanitized(path);
  if (max_width <= 0) return env;
  const MipPyramid pyramid(env);
  int i = 0;
  while (i + 1 < pyramid.levels() && pyramid.level(i).layout.width() > max_width) ++i;
  return pyramid.level(i);
}

struct BakeMethod {
  std::string method = "reference";  // or "mis"
  int samples = 0;                   // mis only
  std::string key() const { return method == "mis" ? "mis" + std::to_string(samples) : method; }
};

struct Baker {
  std::string cache;
  std::string env_name;
  const EnvMap* env;
  BakeMethod method;
  std::unique_ptr<Integrator> integrator;
  Baker(const std::string& cache_dir, const std::string& env_path, const EnvMap& e, const BakeMethod& m)
      : cache(cache_dir),
        env_name(std::filesystem::path(env_path).stem().string()),
        env(&e),
        method(m),
        integrator(make_integrator(m.method, e)) {}

  std::string prefix(const std::string& brdf_name) const {
    return cache + "/" +
           file_key(env_name + "_" + std::to_string(env->layout.width()) + "_" + brdf_name + "_" + method.key());
  }

  MapView bake_view(const Brdf& brdf, const Vec3& v, int size, std::uint64_t seed) const {
    MapView mv;
    mv.view = v.normalized();
    mv.world_from_view = world_from_view_for(mv.view);
    mv.warp = brdf.central_direction();
    mv.material = brdf.spec();
    mv.attributes["method"] = method.key();
    IntegratorOptions o;
    o.samples = std::max(1, method.samples);
    o.seed = seed;
    mv.rgb = integrator->radiance_map(brdf, mv.view, mv.world_from_view, size, o);
    return mv;
  }

  // The map set of `views` (12/42/162) for the BRDF, cached on disk; bake_seconds gets the bake time
  // (as recorded when it was baked).
  MapSet set(const std::string& brdf_name, const Brdf& brdf, int views, int size, double* bake_seconds) const {
    const std::string path = prefix(brdf_name) + "_v" + std::to_string(views) + "_n" + std::to_string(size) + ".exr";
    if (std::filesystem::exists(path)) {
      MapSet s = read_map_set(path);
      const auto it = s.views.front().attributes.find("bakeSeconds");
      *bake_seconds = it == s.views.front().attributes.end() ? 0.0 : std::stod(it->second);
      return s;
    }
    const ViewSet vs = ViewSet::named(view_set_name(views));
    const auto t0 = Clock::now();
    MapSet s;
    for (const Vec3& v : vs.views()) s.views.push_back(bake_view(brdf, v, size, 1));
    *bake_seconds = seconds_since(t0);
    s.views.front().attributes["bakeSeconds"] = std::to_string(*bake_seconds);
    write_map_set(path, s);
    std::cerr << "baked " << path << " in " << *bake_seconds << " s\n";
    return s;
  }

  // One directly baked map (the truth at a novel view), cached.
  cv::Mat direct(const std::string& brdf_name, const Brdf& brdf, const Vec3& v, int index, int size,
                 std::uint64_t seed) const {
    const std::string path = prefix(brdf_name) + "_direct" + std::to_string(index) + "_n" + std::to_string(size) +
                             "_seed" + std::to_string(seed) + ".exr";
    if (std::filesystem::exists(path)) return read_map_set(path).views.front().rgb;
    MapSet s;
    s.views.push_back(bake_view(brdf, v, size, seed));
    write_map_set(path, s);
    return s.views.front().rgb;
  }
};

cv::Mat disc_mask(int size) {
  cv::Mat m(size, size, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < size; ++r) {
    const auto [b, e] = disc_span(r, size, size);
    for (int c = b; c < e; ++c) m.at<unsigned char>(r, c) = 1;
  }
  return m;
}

// `count` random unit directions (seeded) at least min_deg from every direction of `avoid`.
std::vector<Vec3> novel_views(int count, const std::vector<Vec3>& avoid, double min_deg, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> out;
  const double min_cos = std::cos(min_deg * M_PI / 180.0);
  while (int(out.size()) < count) {
    const Vec3 d = Vec3(g(rng), g(rng), g(rng)).normalized();
    bool ok = true;
    for (const Vec3& a : avoid) ok = ok && d.dot(a.normalized()) < min_cos;
    if (ok) out.push_back(d);
  }
  return out;
}

struct WarpChoice {
  std::string name;
  int rings = 0;
  std::unique_ptr<Warp> warp;
};

std::vector<WarpChoice> warps_for(int size) {
  std::vector<WarpChoice> w;
  w.push_back({"exact", 0, std::make_unique<ExactWarp>()});
  w.push_back({"precomputed", 0, std::make_unique<PrecomputedWarp>(size, size)});
  for (int rings : {8, 16, 32}) {
    TessellationOptions t;
    t.rings = rings;
    t.segments = 4 * rings;
    w.push_back({"tessellated", rings, std::make_unique<TessellatedWarp>(size, size, t)});
  }
  return w;
}

struct SetSpec {
  int size, views;
};

std::vector<SetSpec> parse_sets(const std::string& text) {
  std::vector<SetSpec> out;
  for (const std::string& e : split(text)) {
    const auto colon = e.find(':');
    if (colon == std::string::npos) throw std::invalid_argument("--sets wants SIZE:VIEWS items, got '" + e + "'");
    out.push_back({std::stoi(e.substr(0, colon)), std::stoi(e.substr(colon + 1))});
  }
  return out;
}

nlohmann::json run_novel(const std::string& env_path, int env_width, const std::string& brdf_name,
                         const std::vector<SetSpec>& sets, int novel, double min_sep, int reps, int probes,
                         const std::vector<int>& mis_samples, const std::string& cache) {
  const ViewSet dense = ViewSet::named("162");
  const std::vector<Vec3> novel_dirs = novel_views(novel, dense.views(), min_sep, 5);
  const Vec3 up(0, 1, 0);
  const EnvMap full = load_sanitized(env_path);
  const EnvMap env = working_environment(env_path, env_width);
  const Baker baker(cache, env_path, env, BakeMethod{});
  const auto brdf = parse_brdf(brdf_spec(brdf_name));
  nlohmann::json out, rows = nlohmann::json::array(), bakes = nlohmann::json::array(), checks = nlohmann::json::array();
  out["novel_views"] = nlohmann::json::array();
  for (const Vec3& d : novel_dirs) out["novel_views"].push_back({d.x(), d.y(), d.z()});

  // Checks at `probes` texels of the 64^2 map of novel view 0 against the reference quadrature over the
  // FULL environment: the working environment's quadrature bias (common to the map sets and the direct
  // bakes, so it does not enter the blend error), and the noise the MIS integrator would have had.
  {
    const int size = 64;
    const Vec3 v = novel_dirs.front();
    const Mat3 T = world_from_view_for(v);
    const cv::Mat mask = probe_mask(size, probes, 7);
    IntegratorOptions o;
    o.texel_mask = mask;
    auto t0 = Clock::now();
    const cv::Mat truth = make_integrator("reference", full)->radiance_map(*brdf, v, T, size, o);
    const double full_s = seconds_since(t0);
    t0 = Clock::now();
    const cv::Mat working = make_integrator("reference", env)->radiance_map(*brdf, v, T, size, o);
    const double working_s = seconds_since(t0);
    ErrorSums e;
    e.add(working, truth, mask);
    checks.push_back({{"what", "quadrature"},
                      {"env_width", env.layout.width()},
                      {"env_height", env.layout.height()},
                      {"rel_rms", e.relative_rms()},
                      {"seconds_per_texel", working_s / probes},
                      {"full_seconds_per_texel", full_s / probes}});
    const auto mis = make_integrator("mis", full);
    for (int n : mis_samples) {
      o.samples = n;
      o.seed = 1;
      t0 = Clock::now();
      const cv::Mat m = mis->radiance_map(*brdf, v, T, size, o);
      const double mis_s = seconds_since(t0);
      ErrorSums em;
      em.add(m, truth, mask);
      checks.push_back(
          {{"what", "mis"}, {"samples", n}, {"rel_rms", em.relative_rms()}, {"seconds_per_texel", mis_s / probes}});
    }
  }

  for (const SetSpec& spec : sets) {
    const int size = spec.size;
    const cv::Mat disc = disc_mask(size);
    cv::Mat interior(size, size, CV_8UC1, cv::Scalar(0));  // disc radius <= 0.9 (away from the rim)
    for (int r = 0; r < size; ++r)
      for (int c = 0; c < size; ++c)
        interior.at<unsigned char>(r, c) = sphere_map::disc_from_pixel(Vec2(c, r), size, size).norm() <= 0.9;
    std::vector<cv::Mat> directs;
    for (int i = 0; i < novel; ++i)
      directs.push_back(baker.direct(brdf_name, *brdf, novel_dirs[std::size_t(i)], i, size, 2));
    double bake_s = 0;
    const MapSet set = baker.set(brdf_name, *brdf, spec.views, size, &bake_s);
    const ViewSet vs = set.view_set();
    bakes.push_back({{"size", size}, {"views", spec.views}, {"seconds", bake_s}});
    if (size == sets.front().size && spec.views == sets.front().views) {
      // The floor of this measurement: at a source view blend() returns the source map, and the direct
      // bake there is the same deterministic quadrature, so this is 0 unless something is wrong.
      const BlendResult b = blend(set, vs, set.views.front().view, up);
      ErrorSums e;
      e.add(b.rgb, baker.direct(brdf_name, *brdf, set.views.front().view, 1000, size, 2), disc);
      checks.push_back({{"what", "floor"}, {"size", size}, {"rel_rms", e.relative_rms()}, {"worst", e.worst()}});
    }
    const std::vector<WarpChoice> warps = warps_for(size);
    for (const WarpChoice& w : warps) {
      BlendOptions o;
      o.warp = w.warp.get();
      ErrorSums e, inner;
      std::vector<double> times;
      for (int rep = 0; rep < reps; ++rep)
        for (int i = 0; i < novel; ++i) {
          const auto t0 = Clock::now();
          const BlendResult b = blend(set, vs, novel_dirs[std::size_t(i)], up, o);
          times.push_back(seconds_since(t0));
          if (rep > 0) continue;
          if (!b.world_from_view.isApprox(world_from_view_for(novel_dirs[std::size_t(i)], up), 1e-12))
            throw std::logic_error("blend frame differs from the direct bake's frame");
          cv::Mat mask = disc.clone();
          for (int r = 0; r < size; ++r)
            for (int c = 0; c < size; ++c)
              if (!(b.weight.at<float>(r, c) > 0)) mask.at<unsigned char>(r, c) = 0;
          e.add(b.rgb, directs[std::size_t(i)], mask);
          inner.add(b.rgb, directs[std::size_t(i)], mask & interior);
        }
      const double t = median(times);
      rows.push_back({{"env", baker.env_name},
                      {"brdf", brdf_name},
                      {"size", size},
                      {"views", spec.views},
                      {"warp", w.name},
                      {"rings", w.rings},
                      {"rel_rms", e.relative_rms()},
                      {"worst", e.worst()},
                      {"rel_rms_inner", inner.relative_rms()},
                      {"worst_inner", inner.worst()},
                      {"seconds", t}});
      std::cerr << brdf_name << " | " << size << " | " << spec.views << " | " << w.name
                << (w.rings ? std::to_string(w.rings) : "") << ": rel " << e.relative_rms() << " worst " << e.worst()
                << " " << t * 1e3 << " ms\n";
    }
  }
  out["env"] = baker.env_name;
  out["brdf"] = brdf_name;
  out["env_size"] = {env.layout.width(), env.layout.height()};
  out["rows"] = rows;
  out["bakes"] = bakes;
  out["checks"] = checks;
  out["novel"] = novel;
  out["min_separation_deg"] = min_sep;
  out["reps"] = reps;
  out["probes"] = probes;
  return out;
}

void write_f32(const std::string& path, const cv::Mat& m) {
  std::ofstream f(path, std::ios::binary);
  for (int r = 0; r < m.rows; ++r) f.write(reinterpret_cast<const char*>(m.ptr<float>(r)), sizeof(float) * m.cols);
}

nlohmann::json run_render(const std::string& mesh_path, const std::string& env_path, int env_width,
                          const std::string& brdf_name, const std::vector<SetSpec>& specs,
                          const std::vector<double>& fovs, int width, int height, int ref_spp, int ref_seeds, int reps,
                          const std::string& cache, const std::string& heat_prefix, const SetSpec& heat_set,
                          double heat_fov) {
  const Mesh mesh = load_mesh(mesh_path);
  const RayScene scene(mesh);
  const EnvMap env = working_environment(env_path, env_width);
  const ReferenceLighting lighting(env);
  const Baker baker(cache, env_path, env, BakeMethod{});
  const auto brdf = parse_brdf(brdf_spec(brdf_name));
  std::vector<MapSet> sets;
  for (const SetSpec& spec : specs) {
    double bake_s = 0;
    sets.push_back(baker.set(brdf_name, *brdf, spec.views, spec.size, &bake_s));
  }
  nlohmann::json rows = nlohmann::json::array(), refs = nlohmann::json::array();
  for (double fov : fovs) {
    const Camera cam = frame_bounds(mesh.bounds(), -Vec3(0, 0.3, 1), Vec3(0, 1, 0), fov, width, height);
    // The reference as the mean of ref_seeds renders of ref_spp / ref_seeds samples each, in two halves
    // (odd and even seeds). Many seeds, not many samples per seed: render_reference's per-pixel estimate
    // converges, as its spp grows, to a value that depends on the seed (its sub-pixel positions and
    // first-bounce light samples share one Hammersley index, so they are correlated), and only averaging
    // over seeds removes that.
    ReferenceOptions ro;
    ro.spp = std::max(1, ref_spp / ref_seeds);
    ro.shadows = false;
    ro.background = Background::Black;
    auto t0 = Clock::now();
    ReferenceImage a, b;
    for (int k = 0; k < ref_seeds; ++k) {
      ro.seed = std::uint64_t(k + 1);
      const ReferenceImage im = render_reference(scene, *brdf, lighting, cam, ro);
      ReferenceImage& half = k % 2 ? b : a;
      if (half.rgb.empty()) {
        half.rgb = im.rgb / double(ref_seeds / 2);
        half.alpha = im.alpha.clone();
      } else {
        half.rgb += im.rgb / double(ref_seeds / 2);
        half.alpha = cv::min(half.alpha, im.alpha);
      }
    }
    const double ref_s = seconds_since(t0);
    const cv::Mat ref = 0.5 * (a.rgb + b.rgb);
    cv::Mat mask(height, width, CV_8UC1, cv::Scalar(0));
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c)
        mask.at<unsigned char>(r, c) = a.alpha.at<float>(r, c) >= 1.f && b.alpha.at<float>(r, c) >= 1.f;
    ErrorSums noise;
    noise.add(a.rgb, ref, mask);  // A - (A+B)/2 = (A-B)/2: sigma_half/sqrt 2 = the average's noise
    refs.push_back({{"fov", fov},
                    {"spp", ro.spp * ref_seeds},
                    {"seeds", ref_seeds},
                    {"seconds", ref_s},
                    {"noise_rel_rms", noise.relative_rms()},
                    {"pixels", cv::countNonZero(mask)}});
    std::cerr << brdf_name << " fov " << fov << ": reference " << ref_s << " s, noise " << noise.relative_rms() << "\n";
    for (std::size_t k = 0; k < specs.size(); ++k)
      for (RenderMode mode : {RenderMode::Paper, RenderMode::PerPixel}) {
        const SetSpec& spec = specs[k];
        RenderOptions o;
        o.mode = mode;
        o.map_size = spec.size;
        o.warp = "precomputed";
        o.spp = 16;
        const Renderer accurate(mesh, {&sets[k]}, o);
        const cv::Mat img = accurate.render(cam);
        o.spp = 1;
        const Renderer fast(mesh, {&sets[k]}, o);
        const cv::Mat img1 = fast.render(cam);
        std::vector<double> times;
        for (int rep = 0; rep < reps; ++rep) {
          const auto t1 = Clock::now();
          const cv::Mat f = fast.render(cam);
          times.push_back(seconds_since(t1));
        }
        cv::Mat m = mask.clone(), m1 = mask.clone();
        for (int r = 0; r < height; ++r)
          for (int c = 0; c < width; ++c) {
            if (!(img.at<cv::Vec4f>(r, c)[3] >= 1.f)) m.at<unsigned char>(r, c) = 0;
            if (!(img1.at<cv::Vec4f>(r, c)[3] >= 1.f)) m1.at<unsigned char>(r, c) = 0;
          }
        ErrorSums e, e1;
        cv::Mat abs_error;
        e.add(img, ref, m, &abs_error);
        e1.add(img1, ref, m1);
        const std::string mode_name = to_string(mode);
        if (!heat_prefix.empty() && spec.views == heat_set.views && spec.size == heat_set.size &&
            std::abs(fov - heat_fov) < 1e-9)
          write_f32(heat_prefix + "_" + mode_name + ".f32", abs_error / std::sqrt(e.den / double(e.count)));
        rows.push_back({{"fov", fov},
                        {"views", spec.views},
                        {"size", spec.size},
                        {"mode", mode_name},
                        {"rel_rms", e.relative_rms()},
                        {"worst", e.worst()},
                        {"rel_rms_spp1", e1.relative_rms()},
                        {"seconds", median(times)},
                        {"pixels", e.count}});
        std::cerr << "fov " << fov << " | " << spec.views << "@" << spec.size << " | " << mode_name << ": rel "
                  << e.relative_rms() << " (spp1 " << e1.relative_rms() << ") worst " << e.worst() << " "
                  << median(times) * 1e3 << " ms\n";
      }
  }
  nlohmann::json out;
  out["rows"] = rows;
  out["references"] = refs;
  out["brdf"] = brdf_name;
  out["width"] = width;
  out["height"] = height;
  out["ref_spp"] = ref_spp;
  out["reps"] = reps;
  out["env"] = baker.env_name;
  out["env_size"] = {env.layout.width(), env.layout.height()};
  out["mesh"] = std::filesystem::path(mesh_path).filename().string();
  out["heat"] = {
      {"views", heat_set.views}, {"size", heat_set.size}, {"fov", heat_fov}, {"width", width}, {"height", height}};
  return out;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) {
  CLI::App app{"Runtime accuracy: novel-view blend error and render error against the reference (docs/tradeoffs.md)"};
  app.require_subcommand(1);
  std::string out, cache, env, brdf = "ggx 0.2", sets = "64:12,64:42,64:162", mis = "64,256";
  int env_width = 65, novel = 8, reps = 3, probes = 300;
  double min_sep = 3.0;
  auto* nv = app.add_subcommand("novel", "Blend error at novel views against direct bakes");
  nv->add_option("--env", env, "Environment")->required();
  nv->add_option("--env-width", env_width, "Integrate its finest MIP level at most this wide (0: the file)");
  nv->add_option("--brdf", brdf, "BRDF name: lambert, ggx 0.2, ggx 0.05");
  nv->add_option("--sets", sets, "Map sets as SIZE:VIEWS items (views 12, 42, 162)");
  nv->add_option("--novel", novel, "Novel views");
  nv->add_option("--min-separation", min_sep, "Degrees between a novel view and every 162-set view");
  nv->add_option("--reps", reps, "Timing passes over the novel views");
  nv->add_option("--probes", probes, "Texels of the quadrature and MIS checks");
  nv->add_option("--mis", mis, "MIS sample counts of the noise check");
  nv->add_option("--cache", cache, "Folder for baked map sets")->required();
  nv->add_option("--out", out, "JSON output")->required();

  std::string mesh, heat, heat_set = "64:42", fovs = "20,60";
  int width = 640, height = 360, ref_spp = 64, ref_seeds = 16;
  double heat_fov = 60;
  auto* rd = app.add_subcommand("render", "Render error against the reference render");
  rd->add_option("--mesh", mesh, "Mesh")->required();
  rd->add_option("--env", env, "Environment")->required();
  rd->add_option("--env-width", env_width, "As for novel");
  rd->add_option("--brdf", brdf, "BRDF name");
  rd->add_option("--sets", sets, "Map sets as SIZE:VIEWS items");
  rd->add_option("--fovs", fovs, "Vertical fields of view, degrees");
  rd->add_option("--width", width);
  rd->add_option("--height", height);
  rd->add_option("--ref-spp", ref_spp, "Reference samples per pixel in all");
  rd->add_option("--ref-seeds", ref_seeds, "Reference renders (seeds) they are split over; even");
  rd->add_option("--reps", reps, "Timed frames per case");
  rd->add_option("--cache", cache, "Folder for baked map sets")->required();
  rd->add_option("--heat", heat, "Prefix for raw float32 per-pixel error images of one case");
  rd->add_option("--heat-set", heat_set, "SIZE:VIEWS of that case");
  rd->add_option("--heat-fov", heat_fov, "Field of view of that case");
  rd->add_option("--out", out, "JSON output")->required();
  CLI11_PARSE(app, argc, argv);
  if (ref_seeds < 2 || ref_seeds % 2) {
    std::cerr << "rsibr_runtime_tradeoff: --ref-seeds must be even and >= 2\n";
    return 2;
  }
  try {
    std::filesystem::create_directories(cache);
    nlohmann::json result;
    result["threads"] = tbb::info::default_concurrency();
    if (*nv) {
      std::vector<int> mis_samples;
      for (const std::string& e : rsibr::split(mis)) mis_samples.push_back(std::stoi(e));
      result["novel"] = rsibr::run_novel(env, env_width, brdf, rsibr::parse_sets(sets), novel, min_sep, reps, probes,
                                         mis_samples, cache);
    } else {
      std::vector<double> fov_list;
      for (const std::string& f : rsibr::split(fovs)) fov_list.push_back(std::stod(f));
      result["render"] =
          rsibr::run_render(mesh, env, env_width, brdf, rsibr::parse_sets(sets), fov_list, width, height, ref_spp,
                            ref_seeds, reps, cache, heat, rsibr::parse_sets(heat_set).at(0), heat_fov);
    }
    std::ofstream(out) << result.dump(1) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "rsibr_runtime_tradeoff: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
