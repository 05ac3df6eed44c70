// Multi-lobe maps against one mirror-warped map set at the same number of maps (bake/brdf_lobes.h).
// For one BRDF (default: the clear coat of docs/tradeoffs.md) and each environment:
//   truth   the whole BRDF baked directly (MIS, --truth-samples) at --novel view directions that are
//           in no view set (and twice with another seed: the truth's own noise)
//   single  "A":   the whole BRDF baked at view set A, mirror warp (today's rsibr bake)
//   split   "A+B": the normal part at view set A (normal warp) + the mirror part at view set B
//           (mirror warp); the two blends are summed (as runtime/renderer.h sums --maps)
// and each configuration is blended (runtime/blend.h, precomputed warp, up = +Y, the truth's frame)
// at every novel view. Error: relative RMS sqrt(sum |blend - truth|^2 / sum |truth|^2) over RGB of the
// texels inside the disc where every involved blend has weight > 0, pooled over the novel views.
// Times: wall clock of the bakes (TBB's default thread count) and of one blend per novel view.
// View sets: icosa, 42, 162 (ViewSet::named) or fibN (N Fibonacci-sphere points).
//
//   rsibr_multi_lobe --envs a.exr,b.exr --configs fib24,fib6+fib18,fib18 --out rows.json
#include "bake/brdf_lobes.h"
#include "bake/albedo_table.h"
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bench/measure.h"
#include "core/albedo_normalisation.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "core/sphere_map.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/warp.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>

namespace rsibr {
namespace {

using namespace rsibr::bench;

const char* kClearCoat =
    "{type: clearcoat, coat: {ior: 1.5, roughness: 0.05}, flakes: {coverage: 0.3, roughness: 0.3, fresnel: {type: "
    "conductor, eta: [1.66, 0.88, 0.52], k: [9.22, 6.27, 4.84]}}, base: {albedo: [0.5, 0.05, 0.03]}}";

std::vector<Vec3> views_of(const std::string& name) { return ViewSet::named(name).views(); }

struct Baked {
  MapSet set;
  std::vector<float> albedo;  // albedo-normalised maps: the table (core/albedo_normalisation.h)
  ViewSet views;
  double seconds = 0;
};

// Texels whose centre lies inside the disc of the given radius (1: the whole disc).
cv::Mat disc_mask(int size, double radius = 1.0) {
  cv::Mat m(size, size, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c)
      m.at<unsigned char>(r, c) = sphere_map::disc_from_pixel(Vec2(c, r), size, size).squaredNorm() < radius * radius;
  return m;
}

int run(int argc, char** argv) {
  CLI::App app("Multi-lobe maps against one mirror-warped set at the same number of maps");
  std::vector<std::string> envs, configs = {"fib24", "fib6+fib18", "fib18", "fib54", "fib6+fib48", "fib48"};
  std::string out, brdf_text = kClearCoat;
  int res = 64, samples = 256, truth_samples = 1024, novel = 6;
  app.add_option("--envs", envs, "Environments (comma separated)")->required()->delimiter(',');
  app.add_option("--configs", configs, "A (whole BRDF, mirror) or A+B (normal part at A, mirror part at B)")
      ->delimiter(',');
  app.add_option("--brdf", brdf_text, "BRDF spec (YAML text)");
  app.add_option("--res", res, "Map size");
  app.add_option("--samples", samples, "MIS samples per texel of the view-set maps");
  app.add_option("--truth-samples", truth_samples, "MIS samples per texel of the truth");
  app.add_option("--novel", novel, "Novel view directions");
  app.add_option("--out", out, "JSON rows")->required();
  CLI11_PARSE(app, argc, argv);

  const std::shared_ptr<const Brdf> brdf = parse_brdf(brdf_text);
  const auto parts = split_lobes(brdf);
  std::shared_ptr<const Brdf> normal_part, mirror_part;
  for (const auto& p : parts) (p->central_direction() == CentralDirection::Normal ? normal_part : mirror_part) = p;
  const cv::Mat disc = disc_mask(res);
  // The inner disc: normals within 60 degrees of the view (radius sin 60), away from the grazing rim
  // where the coat's Fresnel reflectance rises toward 1 and dominates the whole disc's error.
  const double inner_radius = std::sin(60.0 * kPi / 180);
  const cv::Mat inner = disc_mask(res, inner_radius);
  PrecomputedWarp warp(res, res);
  BlendOptions bo;
  bo.width = bo.height = res;
  bo.warp = &warp;
  const Vec3 up(0, 1, 0);

  // Novel views: random, away from the poles (up hint) and >= 3 degrees from every view of every set.
  std::vector<Vec3> all_views;
  for (const std::string& cfg : configs) {
    std::stringstream ss(cfg.rfind("n:", 0) == 0 ? cfg.substr(2) : cfg);
    std::string name;
    while (std::getline(ss, name, '+'))
      for (const Vec3& v : views_of(name)) all_views.push_back(v);
  }
  std::vector<Vec3> novel_views;
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> g;
  while (int(novel_views.size()) < novel) {
    const Vec3 v = Vec3(g(rng), g(rng), g(rng)).normalized();
    if (std::abs(v.y()) > 0.95) continue;
    double nearest = kPi;
    for (const Vec3& s : all_views) nearest = std::min(nearest, std::acos(std::clamp(v.dot(s), -1.0, 1.0)));
    if (nearest > 3.0 * kPi / 180) novel_views.push_back(v);
  }

  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& env_path : envs) {
    const std::string env_name = std::filesystem::path(env_path).stem().string();
    const EnvMap env = load_sanitized(env_path);
    const auto integrator = make_integrator("mis", env);
    const auto bake = [&](const Brdf& b, const Vec3& v, int n, std::uint64_t seed) {
      IntegratorOptions o;
      o.samples = n;
      o.seed = seed;
      return integrator->radiance_map(b, v, world_from_view_for(v, up), res, o);
    };

    // The truth of each part (seed 1); the whole BRDF's truth is their sum: a part samples with its
    // parent's sampler and pdf (bake/brdf_lobes.h), so with one seed the MIS estimates of the parts
    // add up to the parent's estimate, up to the bright-texel quadrature's order, which follows each
    // part's own lobe width (5e-4 relative under a sun, tests/bake/brdf_lobes_test.cpp; far below
    // the truth's noise). The whole BRDF again with seed 2: the truth's own noise (against the sum),
    // which must be well below the blend errors.
    std::vector<cv::Mat> truth;
    std::vector<std::array<cv::Mat, 2>> truth_part;  // normal, mirror
    ErrorSums noise;
    auto t0 = Clock::now();
    for (const Vec3& v : novel_views) {
      truth_part.push_back({bake(*normal_part, v, truth_samples, 1), bake(*mirror_part, v, truth_samples, 1)});
      truth.push_back(truth_part.back()[0] + truth_part.back()[1]);
      noise.add(bake(*brdf, v, truth_samples, 2), truth.back(), disc);
    }
    const double truth_seconds = seconds_since(t0) / 3;
    std::printf("%s: truth %d views x %d^2, %d samples: %.1f s, noise (seed 1 vs 2) %.2e\n", env_name.c_str(), novel,
                res, truth_samples, truth_seconds, noise.relative_rms());
    std::fflush(stdout);

    std::map<std::string, Baked> cache;  // "<lobe>:<set>"
    const auto baked = [&](const std::string& lobe, const std::string& name, bool normalised) -> const Baked& {
      const std::string key = lobe + ":" + name + (normalised ? ":n" : "");
      auto it = cache.find(key);
      if (it != cache.end()) return it->second;
      const Brdf& b = lobe == "all" ? *brdf : lobe == "normal" ? *normal_part : *mirror_part;
      Baked out{{}, {}, ViewSet(views_of(name)), 0};
      const auto t = Clock::now();
      if (normalised) out.albedo = albedo_table(b);
      for (const Vec3& v : out.views.views()) {
        MapView mv;
        mv.view = v;
        mv.world_from_view = world_from_view_for(v);
        mv.warp = b.central_direction();
        mv.material = b.spec();
        mv.rgb = bake(b, v, samples, 7);
        if (normalised) {
          normalise_by_albedo(mv.rgb, out.albedo);
          mv.albedo = out.albedo;  // blend() multiplies it back at the destination
        }
        out.set.views.push_back(std::move(mv));
      }
      out.seconds = seconds_since(t);
      return cache.emplace(key, std::move(out)).first->second;
    };

    for (const std::string& cfg_text : configs) {
      // "n:" = albedo-normalised maps (every set of the configuration).
      const bool normalised = cfg_text.rfind("n:", 0) == 0;
      const std::string cfg = normalised ? cfg_text.substr(2) : cfg_text;
      const auto plus = cfg.find('+');
      std::vector<const Baked*> sets;
      if (plus == std::string::npos) {
        sets.push_back(&baked("all", cfg, normalised));
      } else {
        sets.push_back(&baked("normal", cfg.substr(0, plus), normalised));
        sets.push_back(&baked("mirror", cfg.substr(plus + 1), normalised));
      }
      int maps = 0;
      double bake_seconds = 0;
      for (const Baked* s : sets) {
        maps += int(s->set.views.size());
        bake_seconds += s->seconds;
      }
      ErrorSums err, err_inner;
      double err_part[2] = {0, 0};  // split: each part's squared error against its own truth
      double worst = 0, blend_seconds = 0;
      for (std::size_t k = 0; k < novel_views.size(); ++k) {
        cv::Mat sum = cv::Mat::zeros(res, res, CV_32FC3), mask = disc.clone();
        std::vector<cv::Mat> blended;
        const auto t = Clock::now();
        for (const Baked* s : sets) {
          const BlendResult r = blend(s->set, s->views, novel_views[k], up, bo);
          sum += r.rgb;
          mask.setTo(0, r.weight <= 0);
          blended.push_back(r.rgb);
        }
        blend_seconds += seconds_since(t);
        if (sets.size() == 2)
          for (int p = 0; p < 2; ++p) {
            ErrorSums s;
            s.add(blended[std::size_t(p)], truth_part[k][std::size_t(p)], mask);
            err_part[p] += s.num;
          }
        ErrorSums one;
        one.add(sum, truth[k], mask);
        err.add(sum, truth[k], mask);
        err_inner.add(sum, truth[k], mask & inner);
        worst = std::max(worst, one.relative_rms());
      }
      std::string sizes;
      for (const Baked* s : sets) sizes += (sizes.empty() ? "" : " + ") + std::to_string(s->set.views.size());
      // Each part's share of the error, relative to the whole truth (the squares add up to about
      // the total's square when the parts' errors are uncorrelated).
      const double part_rel[2] = {err.den > 0 ? std::sqrt(err_part[0] / err.den) : 0.0,
                                  err.den > 0 ? std::sqrt(err_part[1] / err.den) : 0.0};
      std::printf(
          "  %-12s %-8s maps %3d: rel RMS %.4f (inner %.4f, worst view %.4f; normal part %.4f, mirror part %.4f), "
          "bake %.1f s, blend %.2f ms/view\n",
          cfg_text.c_str(), sets.size() == 1 ? "single" : "split", maps, err.relative_rms(), err_inner.relative_rms(),
          worst, part_rel[0], part_rel[1], bake_seconds, 1e3 * blend_seconds / double(novel_views.size()));
      std::fflush(stdout);
      rows.push_back({{"env", env_name},
                      {"config", cfg_text},
                      {"normalised", normalised},
                      {"kind", sets.size() == 1 ? "single" : "split"},
                      {"sets", sizes},
                      {"maps", maps},
                      {"rel_rms", err.relative_rms()},
                      {"rel_rms_inner", err_inner.relative_rms()},
                      {"worst_view", worst},
                      {"normal_part_rel_rms", part_rel[0]},
                      {"mirror_part_rel_rms", part_rel[1]},
                      {"bake_s", bake_seconds},
                      {"blend_ms", 1e3 * blend_seconds / double(novel_views.size())},
                      {"truth_noise", noise.relative_rms()},
                      {"res", res},
                      {"samples", samples},
                      {"truth_samples", truth_samples},
                      {"novel", novel}});
    }
  }
  nlohmann::json doc;
  doc["brdf"] = brdf->spec();
  doc["rows"] = rows;
  std::ofstream(out) << doc.dump(1) << "\n";
  return 0;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) {
  try {
    return rsibr::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "rsibr_multi_lobe: " << e.what() << "\n";
    return 1;
  }
}
