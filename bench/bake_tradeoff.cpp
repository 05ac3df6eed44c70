// Error against time for every integrator and quality knob (issue "Bake", item 6), and the bake
// speed target. Writes JSON rows that bench/bake_tradeoff.py turns into docs/tradeoffs.md tables.
//
// Error: relative RMS, sqrt(sum |a - ref|^2 / sum |ref|^2) over RGB of a fixed random subset of
// disc texels ("probes"), against the reference quadrature over every texel of the full-resolution
// environment at those texels only (IntegratorOptions::texel_mask: a texel's value does not depend
// on the mask). Time: wall clock of the whole map (all texels), TBB's default thread count.
//
//   rsibr_bake_tradeoff --envs a.exr,b.exr --out rows.json            (the knob sweep, one view)
//   rsibr_bake_tradeoff --target ENV.exr --out target.json            (12 views, GGX 0.2 + Fresnel)
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bench/measure.h"
#include "formats/exr_io.h"
#include "core/resample.h"
#include "core/sphere_map.h"
#include "core/view_set.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>

namespace rsibr {
namespace {

using namespace rsibr::bench;

double disc_texel_count(int size) {
  int n = 0;
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) n += sphere_map::disc_from_pixel(Vec2(c, r), size, size).squaredNorm() < 1.0;
  return n;
}

struct Config {
  std::string method;
  std::string knob;  // "samples", "reference_width" or "order"
  int value;
  double lod_bias = 0;  // fis only
};

const std::vector<std::pair<std::string, std::string>>& brdfs() {
  static const std::vector<std::pair<std::string, std::string>> list = {
      {"lambert", "{type: lambert, albedo: [0.8, 0.8, 0.8]}"},
      {"ggx 0.05",
       "{type: ggx, roughness: 0.05, fresnel: {type: conductor, eta: [0.2, 0.92, 1.1], k: [3.9, 2.45, 2.14]}}"},
      {"ggx 0.2",
       "{type: ggx, roughness: 0.2, fresnel: {type: conductor, eta: [0.2, 0.92, 1.1], k: [3.9, 2.45, 2.14]}}"},
      {"ggx 0.5",
       "{type: ggx, roughness: 0.5, fresnel: {type: conductor, eta: [0.2, 0.92, 1.1], k: [3.9, 2.45, 2.14]}}"},
      {"clear coat",
       "{type: clearcoat, coat: {ior: 1.5, roughness: 0.05}, flakes: {coverage: 0.3, roughness: 0.3, "
       "fresnel: {type: conductor, eta: [1.66, 0.88, 0.52], k: [9.22, 6.27, 4.84]}}, base: {albedo: [0.5, 0.05, 0.03]}}"},
  };
  return list;
}

std::vector<Config> configs(const std::string& brdf_name, bool quick) {
  std::vector<Config> out;
  const std::vector<int> mis = quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 16, 64, 256};
  const std::vector<int> fis = quick ? std::vector<int>{8, 32} : std::vector<int>{8, 32, 128, 512};
  const std::vector<int> ref = quick ? std::vector<int>{32, 64} : std::vector<int>{32, 64, 128};
  for (int w : ref) out.push_back({"reference", "reference_width", w});
  for (int n : mis) out.push_back({"mis", "samples", n});
  for (int n : fis) out.push_back({"fis", "samples", n});
  out.push_back({"fis", "samples", 32, 1.0});  // the LOD-bias knob
  if (brdf_name == "lambert") out.push_back({"sh", "order", 2});
  return out;
}

nlohmann::json sweep(const std::vector<std::string>& envs, int size, int probes, bool quick,
                     const std::string& only_brdf, const std::string& only_config) {
  nlohmann::json rows = nlohmann::json::array();
  const Vec3 view = Vec3(0.3, 0.4, 0.866).normalized();  // a generic view (not a symmetry axis)
  const Mat3 T = world_from_view_for(view);
  const cv::Mat mask = probe_mask(size, probes, 7);
  for (const std::string& path : envs) {
    const EnvMap env = load_sanitized(path);
    const std::string env_name = std::filesystem::path(path).stem().string();
    std::map<std::string, std::unique_ptr<Integrator>> integrators;
    for (const char* m : {"reference", "mis", "fis", "sh"}) integrators[m] = make_integrator(m, env);
    for (const auto& [brdf_name, spec] : brdfs()) {
      if (!only_brdf.empty() && brdf_name != only_brdf) continue;
      const auto brdf = parse_brdf(spec);
      IntegratorOptions ref_options;
      ref_options.texel_mask = mask;
      auto t0 = Clock::now();
      const cv::Mat ref = integrators["reference"]->radiance_map(*brdf, view, T, size, ref_options);
      const double ref_probe_seconds = seconds_since(t0);
      const double disc_texels = disc_texel_count(size);
      for (const Config& c : configs(brdf_name, quick)) {
        if (!only_config.empty() && only_config != c.method + ":" + std::to_string(c.value)) continue;
        IntegratorOptions o;
        o.seed = 1;
        if (c.knob == "samples") o.samples = c.value;
        if (c.knob == "reference_width") o.reference_width = c.value;
        o.fis_lod_bias = c.lod_bias;
        t0 = Clock::now();
        const cv::Mat map = integrators[c.method]->radiance_map(*brdf, view, T, size, o);
        const double secs = seconds_since(t0);
        ErrorSums e;
        e.add(map, ref, mask);
        rows.push_back({{"env", env_name},
                        {"brdf", brdf_name},
                        {"method", c.method},
                        {"knob", c.knob},
                        {"value", c.value},
                        {"lod_bias", c.lod_bias},
                        {"seconds", secs},
                        {"rel_rms", e.relative_rms()}});
        std::cerr << env_name << " | " << brdf_name << " | " << c.method << " " << c.knob << "=" << c.value << ": "
                  << e.relative_rms() << " in " << secs << " s\n";
      }
      // The full reference, extrapolated from the probes (its cost per texel is constant).
      rows.push_back({{"env", env_name},
                      {"brdf", brdf_name},
                      {"method", "reference"},
                      {"knob", "reference_width"},
                      {"value", env.layout.width()},
                      {"seconds", ref_probe_seconds * disc_texels / probes},
                      {"rel_rms", 0.0},
                      {"extrapolated", true}});
    }
  }
  return rows;
}

nlohmann::json target(const std::string& env_path, int size, int probes) {
  // 1024 x 512 as the bake speed target specifies (the CC0 maps are 512 x 256: bilinear enlargement, no new detail).
  const EnvMap env = resample(load_sanitized(env_path), Layout(LayoutKind::LatLong, 1024, 512));
  const auto brdf = parse_brdf(brdfs()[2].second);
  const ViewSet views = ViewSet::named("icosa");
  const cv::Mat mask = probe_mask(size, probes, 11);
  const double disc_texels = disc_texel_count(size);
  nlohmann::json out;
  out["env"] = std::filesystem::path(env_path).stem().string();
  out["env_size"] = {1024, 512};
  out["views"] = int(views.views().size());
  out["size"] = size;
  out["threads"] = tbb::info::default_concurrency();
  out["brdf"] = brdf->spec();
  // Reference at the probes of every view.
  const auto reference = make_integrator("reference", env);
  std::vector<cv::Mat> refs;
  auto t0 = Clock::now();
  for (int v = 0; v < int(views.views().size()); ++v) {
    IntegratorOptions o;
    o.texel_mask = mask;
    const Vec3 d = views.views()[std::size_t(v)];
    refs.push_back(reference->radiance_map(*brdf, d, world_from_view_for(d), size, o));
  }
  const double ref_seconds = seconds_since(t0) * disc_texels / probes;
  out["reference_seconds_extrapolated"] = ref_seconds;
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [method, samples] :
       std::vector<std::pair<std::string, int>>{{"fis", 16}, {"fis", 32}, {"fis", 64}, {"mis", 64}, {"mis", 256}}) {
    t0 = Clock::now();
    const auto integrator = make_integrator(method, env);  // its precomputation is part of the cost
    ErrorSums e;
    std::vector<cv::Mat> maps;
    for (int v = 0; v < int(views.views().size()); ++v) {
      IntegratorOptions o;
      o.samples = samples;
      o.seed = 3;
      const Vec3 d = views.views()[std::size_t(v)];
      maps.push_back(integrator->radiance_map(*brdf, d, world_from_view_for(d), size, o));
    }
    const double secs = seconds_since(t0);
    for (int v = 0; v < int(views.views().size()); ++v) e.add(maps[std::size_t(v)], refs[std::size_t(v)], mask);
    rows.push_back({{"method", method},
                    {"samples", samples},
                    {"seconds", secs},
                    {"rel_rms", e.relative_rms()},
                    {"speedup_vs_reference", ref_seconds / secs}});
    std::cerr << method << " " << samples << ": " << e.relative_rms() << " in " << secs << " s (" << ref_seconds / secs
              << "x the reference)\n";
  }
  out["rows"] = rows;
  return out;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) {
  CLI::App app{"Bake integrators: error against time (docs/tradeoffs.md) and the 12-view speed target"};
  std::string envs, target_env, out;
  int size = 256, probes = 1500;
  bool quick = false;
  std::string only_brdf;
  app.add_option("--brdf", only_brdf, "Only this BRDF of the sweep (e.g. 'ggx 0.2')");
  std::string only_config;
  app.add_option("--config", only_config, "Only this configuration of the sweep (method:value, e.g. fis:512)");
  app.add_option("--envs", envs, "Comma-separated environments for the knob sweep");
  app.add_option("--target", target_env, "Environment for the 12-view target run");
  app.add_option("--out", out, "JSON output")->required();
  app.add_option("--size", size, "Sphere-map size");
  app.add_option("--probes", probes, "Texels where the error is measured");
  app.add_flag("--quick", quick, "Fewer knob values");
  CLI11_PARSE(app, argc, argv);
  nlohmann::json result;
  if (!envs.empty()) {
    std::vector<std::string> list;
    std::stringstream ss(envs);
    for (std::string e; std::getline(ss, e, ',');) list.push_back(e);
    result["sweep"] = rsibr::sweep(list, size, probes, quick, only_brdf, only_config);
    result["size"] = size;
    result["probes"] = probes;
    result["threads"] = tbb::info::default_concurrency();
  }
  if (!target_env.empty()) result["target"] = rsibr::target(target_env, size, probes);
  std::ofstream(out) << result.dump(1) << "\n";
  return 0;
}
