// The light probe's error against the true environment (bench/probe_accuracy.py runs it on the
// synthetic datasets and writes the docs/tradeoffs.md section "Light probe accuracy").
//
//   rsibr_probe_accuracy PROBE.exr TRUTH.exr [--camera X,Y,Z]... [--sun-cap-deg 10] [--camera-cap-deg 15]
//
// The truth is resampled (solid-angle area average, core/resample.h) into the probe's lat-long
// grid. Texels the probe did not cover (all channels 0) are left out. A per-channel gain g_c (the
// merged views' exposure and white balance are unknown) is fitted by least squares over the covered
// texels outside the sun's cap: g_c = sum w a b / sum w a^2 (w = solid angle). Reported (JSON on
// stdout), each a relative RMS sqrt(sum w |g a - b|^2 / sum w |b|^2) over the three channels:
//   all         every covered texel (the sun included: dominated by it)
//   no_sun      outside the cap of --sun-cap-deg around the truth's brightest texel
//   cameras     inside caps of --camera-cap-deg around the given directions (from the ball towards
//               each camera: where the camera and photographer reflect), outside the sun's cap
//   no_rig      outside the sun's cap and the --occluder caps (the rig's other balls, which the
//               chrome ball reflects and extract does not mask)
// the log RMS in stops outside the sun's cap (eps = 1% of the truth's median level; its own gain,
// fitted in the log domain), the sun's
// energy in the probe relative to the truth's (sum over the sun's cap of w g a over w b,
// channel mean: below 1 where the brightest bracket clipped the sun), and the covered solid-angle
// fraction.
#include "core/env_map.h"
#include "formats/exr_io.h"
#include "core/resample.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <vector>

namespace {

using rsibr::Vec3;

Vec3 parse_direction(const std::string& s) {
  std::stringstream ss(s);
  std::array<double, 3> v{};
  char comma = 0;
  if (!(ss >> v[0] >> comma >> v[1] >> comma >> v[2]) || !(Vec3(v[0], v[1], v[2]).norm() > 0))
    throw std::invalid_argument("--camera: expected X,Y,Z (non-zero), got '" + s + "'");
  return Vec3(v[0], v[1], v[2]).normalized();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Light probe error against the true environment");
  std::string probe_path, truth_path;
  std::vector<std::string> cameras, occluders;
  double sun_cap_deg = 10, camera_cap_deg = 15;
  app.add_option("probe", probe_path, "Probe (lat-long EXR, rsibr probe)")->required();
  app.add_option("truth", truth_path, "True environment (any layout)")->required();
  app.add_option("--camera", cameras, "Direction from the ball towards a camera (world), X,Y,Z; repeatable");
  app.add_option("--occluder", occluders, "A cap left out of no_rig: X,Y,Z,HALF_ANGLE_DEG (world); repeatable");
  app.add_option("--sun-cap-deg", sun_cap_deg, "Half angle of the cap around the sun left out of no_sun");
  app.add_option("--camera-cap-deg", camera_cap_deg, "Half angle of the caps around the camera directions");
  CLI11_PARSE(app, argc, argv);
  try {
    const rsibr::EnvMap probe = rsibr::read_environment(probe_path, rsibr::LayoutKind::LatLong);
    rsibr::EnvMap truth = rsibr::read_environment(truth_path);
    cv::max(truth.pixels, 0.0, truth.pixels);  // the synth's "sanitize": negatives are zero
    const rsibr::EnvMap t = rsibr::resample(truth, probe.layout);
    std::vector<Vec3> cams;
    for (const std::string& c : cameras) cams.push_back(parse_direction(c));
    std::vector<std::pair<Vec3, double>> caps;  // (direction, cos of the half angle)
    for (const std::string& o : occluders) {
      const std::size_t last = o.rfind(',');
      if (last == std::string::npos) throw std::invalid_argument("--occluder: expected X,Y,Z,DEG, got '" + o + "'");
      caps.push_back({parse_direction(o.substr(0, last)), std::cos(std::stod(o.substr(last + 1)) * M_PI / 180)});
    }

    const rsibr::Layout& l = probe.layout;
    const int w = l.width(), h = l.height();
    // The sun: the truth's brightest texel (channel sum).
    Vec3 sun = Vec3::UnitY();
    double peak = -1;
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const cv::Vec3f b = t.pixels.at<cv::Vec3f>(r, c);
        if (b[0] + b[1] + b[2] > peak) peak = b[0] + b[1] + b[2], sun = *l.texel_direction(c, r);
      }
    const double cos_sun = std::cos(sun_cap_deg * M_PI / 180), cos_cam = std::cos(camera_cap_deg * M_PI / 180);

    struct Texel {
      cv::Vec3f a, b;
      double w;
      bool sun, cam, rig;
    };
    std::vector<Texel> texels;
    double covered = 0, total = 0;
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const double omega = l.texel_solid_angle(c, r);
        total += omega;
        const cv::Vec3f a = probe.pixels.at<cv::Vec3f>(r, c);
        if (a[0] == 0 && a[1] == 0 && a[2] == 0) continue;
        covered += omega;
        const Vec3 d = *l.texel_direction(c, r);
        bool cam = false;
        for (const Vec3& k : cams) cam = cam || d.dot(k) >= cos_cam;
        bool rig = false;
        for (const auto& [k, cos_half] : caps) rig = rig || d.dot(k) >= cos_half;
        texels.push_back({a, t.pixels.at<cv::Vec3f>(r, c), omega, d.dot(sun) >= cos_sun, cam, rig});
      }
    std::array<double, 3> gain{1, 1, 1};
    for (int ch = 0; ch < 3; ++ch) {
      double ab = 0, aa = 0;
      for (const Texel& x : texels)
        if (!x.sun) ab += x.w * x.a[ch] * x.b[ch], aa += x.w * x.a[ch] * x.a[ch];
      gain[ch] = aa > 0 ? ab / aa : 1.0;
    }
    auto rel_rms = [&](auto&& keep) {
      double e2 = 0, b2 = 0;
      for (const Texel& x : texels)
        if (keep(x))
          for (int ch = 0; ch < 3; ++ch) {
            const double d = gain[ch] * x.a[ch] - x.b[ch];
            e2 += x.w * d * d;
            b2 += x.w * double(x.b[ch]) * x.b[ch];
          }
      return b2 > 0 ? std::sqrt(e2 / b2) : 0.0;
    };
    const double all = rel_rms([](const Texel&) { return true; });
    const double no_sun = rel_rms([](const Texel& x) { return !x.sun; });
    const double at_cameras = rel_rms([](const Texel& x) { return x.cam && !x.sun; });
    const double no_rig = rel_rms([](const Texel& x) { return !x.sun && !x.rig; });
    // Log error in stops outside the sun, eps = 1% of the truth's solid-angle-weighted median level
    // (channel mean): the shape error where the relative RMS is dominated by a few bright lamps.
    std::vector<std::pair<double, double>> levels;  // (level, weight)
    double wsum = 0;
    for (const Texel& x : texels)
      if (!x.sun) levels.push_back({(x.b[0] + x.b[1] + x.b[2]) / 3.0, x.w}), wsum += x.w;
    std::sort(levels.begin(), levels.end());
    double median = 0, acc = 0;
    for (const auto& [level, weight] : levels)
      if ((acc += weight) >= 0.5 * wsum) {
        median = level;
        break;
      }
    const double eps = std::max(1e-2 * median, 1e-30);
    // Its own gain, fitted in the log domain (the least-squares gain above follows the bright texels):
    // a few fixed-point steps of g_c *= 2^-(mean log2 error of channel c).
    std::array<double, 3> log_gain = gain;
    auto log_error = [&](const Texel& x, int ch) {
      return std::log2((log_gain[ch] * std::max(0.0f, x.a[ch]) + eps) / (std::max(0.0f, x.b[ch]) + eps));
    };
    for (int iteration = 0; iteration < 8; ++iteration)
      for (int ch = 0; ch < 3; ++ch) {
        double sum = 0, ws = 0;
        for (const Texel& x : texels)
          if (!x.sun) sum += x.w * log_error(x, ch), ws += x.w;
        if (ws > 0) log_gain[ch] *= std::exp2(-sum / ws);
      }
    auto log_rms_where = [&](auto&& keep) {
      double log2_sum = 0, log_w = 0;
      for (const Texel& x : texels)
        if (keep(x))
          for (int ch = 0; ch < 3; ++ch) {
            const double d = log_error(x, ch);
            log2_sum += x.w * d * d;
            log_w += x.w;
          }
      return log_w > 0 ? std::sqrt(log2_sum / log_w) : 0.0;
    };
    const double log_rms = log_rms_where([](const Texel& x) { return !x.sun; });
    const double log_rms_no_rig = log_rms_where([](const Texel& x) { return !x.sun && !x.rig; });
    double sun_a = 0, sun_b = 0;
    for (const Texel& x : texels)
      if (x.sun)
        for (int ch = 0; ch < 3; ++ch) sun_a += x.w * gain[ch] * x.a[ch], sun_b += x.w * x.b[ch];
    const double sun_energy = sun_b > 0 ? sun_a / sun_b : 0.0;
    std::printf(
        "{\"covered_fraction\": %.6f, \"all\": %.6f, \"no_sun\": %.6f, \"cameras\": %.6f, \"no_rig\": %.6f, \"sun_energy\": %.6f, \"log_rms_stops\": %.6f, \"log_rms_no_rig_stops\": %.6f, \"gain\": [%.6g, %.6g, %.6g], "
        "\"sun\": [%.5f, %.5f, %.5f]}\n",
        covered / total, all, no_sun, at_cameras, no_rig, sun_energy, log_rms, log_rms_no_rig, gain[0], gain[1],
        gain[2], sun.x(), sun.y(), sun.z());
  } catch (const std::exception& e) {
    std::cerr << "rsibr_probe_accuracy: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
