// A rsibr process run on a synthetic shoot against the shoot's truth, for the light recovered where
// the chrome ball clipped (bench/source_recovery.py runs it over held-out shoots and writes the
// docs/tradeoffs.md section "Clipped light sources (rsibr process)").
//
//   rsibr_source_recovery SYNTH_DIR PROCESS_DIR     (JSON on stdout)
//
// Units: the merged images hold L * u_c with u_c = gain_normalised * (white balance x vignetting at
// the pixel)_c * s_c (capture/synth_capture.h); u is read per view as the ratio of the truth's
// <view>_radiance.exr to <view>_scene.exr at each ball's centre pixel, times gain_normalised, times
// s_c, the recovered response's scale against the true one: the median over the codes from a
// quarter to three quarters of the range of the recovered curve's knot over the true relative
// exposure (PROCESS_DIR/hdr/response.json, SYNTH_DIR/truth/response.csv). The merge ties the
// channels at the middle code (equal mid-grey codes stay neutral, hdr/response_recovery.h), so a
// camera whose curves differ per channel there (the synthetic "measured" response) has s_c != 1:
// a convention of the merge's unit that no photograph can reveal, not an error of it. The
// probe is compared in the chrome ball's units (u averaged over the views), the grey maps in the
// grey ball's (per view). Reported:
//   probe_ratio[c]          int probe.exr / (u_c int L_true), per channel (1: the light is all there)
//   measured_ratio[c]       the same for probe-measured.exr (before the recovery)
//   computed_vs_truth       computed grey maps / u against the true grey maps: relative RMS after
//                           the global gain fit (compare/map_compare.h) and without it (calibrated)
//   sun                     the truth's brightest source (its power-weighted centroid within 3
//                           degrees of the brightest texel; `power` there) and the most powerful
//                           recovered source: angle (degrees) and its sigma; `needed`, the truth
//                           minus the measured probe inside caps around the clipped regions (their
//                           radius + 2 degrees): what the sources had to supply (the probe keeps the
//                           unclipped edges of a light; its holes elsewhere, under the stand, are no
//                           source's to fill); `recovered`, the sources'
//                           summed power and its sigma; power_ratio = recovered / needed per channel;
//                           error_over_sigma = (recovered - needed) / sigma
#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "formats/exr_io.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "formats/truth_image.h"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace fs = std::filesystem;
using namespace rsibr;

namespace {

Vec3 integral3(const EnvMap& e) {
  const std::vector<double> v = integral(e);
  return Vec3(v[0], v[1], v[2]);
}

cv::Vec3f pixel(const cv::Mat& m, const Vec2& p) {
  const int x = std::clamp(int(std::lround(p.x())), 0, m.cols - 1),
            y = std::clamp(int(std::lround(p.y())), 0, m.rows - 1);
  return m.at<cv::Vec3f>(y, x);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: rsibr_source_recovery SYNTH_DIR PROCESS_DIR\n";
    return 2;
  }
  try {
    const fs::path synth = argv[1], process = argv[2];
    const YAML::Node truth = YAML::LoadFile((synth / "truth" / "truth.yaml").string());
    const SynthScene scene = load_synth_scene(truth["scene"].as<std::string>());
    const EnvMap env = synth_environment(scene);
    const double gain = truth["camera"]["gain_normalised"].as<double>();
    // Per view and ball: u_c at the ball's centre pixel.
    std::map<std::string, std::map<std::string, Vec3>> unit;
    Vec3 chrome_unit = Vec3::Zero();
    int chrome_views = 0;
    for (const auto& v : truth["views"]) {
      const std::string name = v["name"].as<std::string>();
      const cv::Mat rad = read_truth_image(synth / "truth" / v["radiance"].as<std::string>());
      const cv::Mat sc = read_truth_image(synth / "truth" / v["scene_radiance"].as<std::string>());
      for (const auto& b : v["balls"]) {
        const auto c = b["centre_px"].as<std::vector<double>>();
        const cv::Vec3f a = pixel(rad, Vec2(c[0], c[1])), s = pixel(sc, Vec2(c[0], c[1]));
        Vec3 u;
        for (int k = 0; k < 3; ++k) u[k] = s[k] > 0 ? gain * a[k] / s[k] : gain;
        unit[name][b["name"].as<std::string>()] = u;
        if (b["name"].as<std::string>() == "chrome") chrome_unit += u, ++chrome_views;
      }
    }
    if (chrome_views) chrome_unit /= chrome_views;
    // s_c: the recovered response's scale against the truth's, where the curve is best constrained.
    Vec3 response_scale = Vec3::Ones();
    if (fs::exists(process / "hdr" / "response.json") && fs::exists(synth / "truth" / "response.csv")) {
      std::ifstream rj(process / "hdr" / "response.json");
      const nlohmann::json response = nlohmann::json::parse(rj);
      std::ifstream tc(synth / "truth" / "response.csv");
      std::vector<std::array<double, 3>> true_x;
      std::string line;
      std::getline(tc, line);  // header: code,R,G,B
      while (std::getline(tc, line)) {
        std::array<double, 3> x{};
        if (std::sscanf(line.c_str(), "%*d,%lf,%lf,%lf", &x[0], &x[1], &x[2]) == 3) true_x.push_back(x);
      }
      const auto& knots = response.at("knots");
      const int max_code = response.at("max_code").get<int>();
      // One knot per code (8-bit shoots; other knot layouts keep s = 1).
      for (int c = 0; c < 3 && int(knots.at(c).size()) == max_code + 1; ++c) {
        std::vector<double> r;
        for (int code = max_code / 4; code <= 3 * max_code / 4; ++code)
          if (code < int(true_x.size()) && code < int(knots.at(c).size()) && true_x[code][c] > 0)
            r.push_back(knots.at(c).at(code).get<double>() / true_x[code][c]);
        if (r.empty()) continue;
        std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
        response_scale[c] = r[r.size() / 2];
      }
      for (auto& [view, balls] : unit)
        for (auto& [ball, u] : balls) u = u.cwiseProduct(response_scale);
      chrome_unit = chrome_unit.cwiseProduct(response_scale);
    }
    const Vec3 truth_integral = integral3(env).cwiseProduct(chrome_unit);
    nlohmann::json out;
    out["response_scale"] = {response_scale[0], response_scale[1], response_scale[2]};
    auto ratio = [&](const fs::path& p) {
      const Vec3 i = integral3(read_environment(p.string()));
      return nlohmann::json::array({i[0] / truth_integral[0], i[1] / truth_integral[1], i[2] / truth_integral[2]});
    };
    out["probe_ratio"] = ratio(process / "probe.exr");
    if (fs::exists(process / "probe-measured.exr")) out["measured_ratio"] = ratio(process / "probe-measured.exr");

    // Computed grey maps against the truth (each view's map divided by its unit).
    for (const auto& b : truth["balls"]) {
      if (b["kind"].as<std::string>() != "grey") continue;
      const std::string ball = b["name"].as<std::string>();
      const fs::path computed = process / "maps" / ("computed-" + ball + ".exr");
      if (!fs::exists(computed)) continue;
      MapSet c = read_map_set(computed.string());
      MapSet cap = read_map_set((process / "maps" / ("captured-" + ball + ".exr")).string());
      MapSet t = read_map_set((synth / "truth" / "maps" / (ball + ".exr")).string());
      // The truth at the computed maps' size: each texel the mean of the finer texels inside the disc.
      for (MapView& mv : t.views) {
        const int n = c.width();
        if (mv.rgb.cols == n || mv.rgb.cols % n) continue;
        const int k = mv.rgb.cols / n;
        cv::Mat small(n, n, CV_32FC3, cv::Scalar::all(0));
        for (int r = 0; r < n; ++r)
          for (int q = 0; q < n; ++q) {
            Vec3 sum = Vec3::Zero();
            int count = 0;
            for (int a = 0; a < k; ++a)
              for (int b = 0; b < k; ++b) {
                const int rr = r * k + a, cc = q * k + b;
                const double x = (2.0 * cc + 1) / mv.rgb.cols - 1, y = 1 - (2.0 * rr + 1) / mv.rgb.rows;
                if (x * x + y * y >= 1) continue;
                const cv::Vec3f p = mv.rgb.at<cv::Vec3f>(rr, cc);
                sum += Vec3(p[0], p[1], p[2]), ++count;
              }
            if (count)
              small.at<cv::Vec3f>(r, q) =
                  cv::Vec3f(float(sum[0] / count), float(sum[1] / count), float(sum[2] / count));
          }
        mv.rgb = small;
      }
      for (MapSet* set : {&c, &cap})
        for (MapView& mv : set->views) {
          const std::string image = mv.image;
          const Vec3 u = unit.count(image) && unit[image].count(ball)
                             ? unit[image][ball]
                             : Vec3(Vec3::Constant(gain).cwiseProduct(response_scale));
          mv.rgb.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
            for (int k = 0; k < 3; ++k) p[k] = float(p[k] / u[k]);
          });
        }
      // Views whose ball was not found where the truth has it (the extracted view more than 2
      // degrees off: a wrong detection) are left out and counted.
      int dropped = 0;
      for (MapSet* set : {&c, &cap}) {
        MapSet kept;
        for (MapView& mv : set->views) {
          bool near = false;
          for (const MapView& tv : t.views) near = near || angle_between(mv.view, tv.view) < 2 * kPi / 180;
          if (near)
            kept.views.push_back(std::move(mv));
          else if (set == &c)
            ++dropped;
        }
        *set = std::move(kept);
      }
      out["views_left_out"][ball] = dropped;
      if (c.views.empty() || cap.views.empty()) continue;
      CompareOptions co;
      co.view_tolerance_deg = 2.0;
      const Comparison fit = compare_map_sets(c, t, co);
      co.fit = false;
      const Comparison raw = compare_map_sets(c, t, co);
      out["computed_vs_truth"][ball] = {{"after_fit", fit.after.relative_rms},
                                        {"calibrated", raw.before.relative_rms},
                                        {"gains", fit.fit ? nlohmann::json(fit.fit->gains) : nlohmann::json()}};
      co.fit = true;
      const Comparison capt = compare_map_sets(cap, t, co);
      nlohmann::json per_view = nlohmann::json::array();
      for (const PairComparison& pc : capt.pairs) per_view.push_back(pc.after.relative_rms);
      out["captured_vs_truth"][ball] = {{"after_fit", capt.after.relative_rms}, {"views", per_view}};
    }

    // The truth's brightest source.
    const Layout& lay = env.layout;
    double best = -1;
    Vec3 best_dir = Vec3::UnitY();
    for (int r = 0; r < lay.height(); ++r)
      for (int c = 0; c < lay.width(); ++c) {
        const float* p = env.pixels.ptr<float>(r) + c * env.channels();
        const double y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        if (y > best) best = y, best_dir = lay.texel_direction(c, r)->normalized();
      }
    Vec3 power = Vec3::Zero(), centroid = Vec3::Zero();
    for (int r = 0; r < lay.height(); ++r)
      for (int c = 0; c < lay.width(); ++c) {
        const Vec3 w = lay.texel_direction(c, r)->normalized();
        if (angle_between(w, best_dir) * 180 / kPi >= 3) continue;
        const float* p = env.pixels.ptr<float>(r) + c * env.channels();
        const double om = lay.texel_solid_angle(c, r);
        const Vec3 L(p[0], p[1], p[2]);
        power += om * L;
        centroid += om * (0.2126 * L[0] + 0.7152 * L[1] + 0.0722 * L[2]) * w;
      }
    power = power.cwiseProduct(chrome_unit);
    nlohmann::json sun = {
        {"direction", {centroid.normalized().x(), centroid.normalized().y(), centroid.normalized().z()}},
        {"power", {power[0], power[1], power[2]}}};
    // The recovered sources, summed, against what they had to supply; the direction of the most
    // powerful source against the sun's.
    const fs::path record = process / "steps" / "sources.json";
    if (fs::exists(record) && fs::exists(process / "probe-measured.exr")) {
      std::ifstream in(record);
      const nlohmann::json rec = nlohmann::json::parse(in);
      const auto& sources = rec["summary"]["sources"];
      // Inside caps around the clipped regions (each its radius + 2 degrees): far from them the
      // measured probe's own holes (the stand's directions) are no source's to fill.
      std::vector<std::pair<Vec3, double>> caps;
      for (const auto& rg : rec["summary"]["regions"])
        caps.push_back(
            {Vec3(rg["direction"][0].get<double>(), rg["direction"][1].get<double>(), rg["direction"][2].get<double>()),
             (rg["radius_deg"].get<double>() + 2) * kPi / 180});
      auto in_caps = [&](const EnvMap& e, const Vec3& scale) {
        Vec3 p = Vec3::Zero();
        for (int r = 0; r < e.layout.height(); ++r)
          for (int c = 0; c < e.layout.width(); ++c) {
            const Vec3 w = *e.layout.texel_direction(c, r);
            bool in = false;
            for (const auto& [d, radius] : caps) in = in || angle_between(w, d) <= radius;
            if (!in) continue;
            const float* v = e.pixels.ptr<float>(r) + c * e.channels();
            p += e.layout.texel_solid_angle(c, r) * Vec3(v[0], v[1], v[2]).cwiseProduct(scale);
          }
        return p;
      };
      const Vec3 need = in_caps(env, chrome_unit) -
                        in_caps(read_environment((process / "probe-measured.exr").string()), Vec3::Ones());
      Vec3 total = Vec3::Zero(), variance = Vec3::Zero();
      double strongest = -1;
      for (const auto& src : sources) {
        Vec3 p, sg;
        for (int k = 0; k < 3; ++k)
          p[k] = src["power"][std::size_t(k)].get<double>(), sg[k] = src["power_sigma"][std::size_t(k)].get<double>();
        total += p, variance += sg.cwiseAbs2();
        if (p.sum() <= strongest) continue;
        strongest = p.sum();
        const Vec3 d(src["direction"][0].get<double>(), src["direction"][1].get<double>(),
                     src["direction"][2].get<double>());
        sun["angle_deg"] = angle_between(d, centroid.normalized()) * 180 / kPi;
        sun["direction_sigma_deg"] = src["direction_sigma_deg"];
      }
      sun["needed"] = {need[0], need[1], need[2]};
      sun["recovered"] = {total[0], total[1], total[2]};
      sun["recovered_sigma"] = {std::sqrt(variance[0]), std::sqrt(variance[1]), std::sqrt(variance[2])};
      if (!sources.empty()) {
        sun["power_ratio"] = {total[0] / need[0], total[1] / need[1], total[2] / need[2]};
        nlohmann::json z = nlohmann::json::array();
        for (int k = 0; k < 3; ++k) z.push_back(variance[k] > 0 ? (total[k] - need[k]) / std::sqrt(variance[k]) : 0.0);
        sun["error_over_sigma"] = z;
      }
      out["sources"] = sources.size();
      out["regions"] = rec["summary"]["regions"].size();
    }
    out["sun"] = sun;
    std::cout << out.dump(1) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "rsibr_source_recovery: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
