// rsibr process on shoots whose sun is clipped in every bracket (the chrome ball's reflection of a
// sun of 5e5 against a sky of ~1; 7 brackets 2 EV apart cannot reach it): the sources step finds
// it, recovers it from the grey ball and writes it into the probe. Checked against the shoot's
// truth: the probe's integral per channel, the computed grey maps, captured against computed,
// the report's account; and with --no-sources, today's probe. Two shoots (sun elevation, seed,
// sky), 320x240 pinhole, 3 views 120 degrees apart, the poses from the truth. The sun is 1.2 degrees
// across and the renderer takes 3 x 3 samples per pixel: a smaller sun is missed by every sample
// of some pixels (capture/ point-samples within a pixel), which no camera does.
#include "pipeline/process_pipeline.h"

#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "formats/exr_io.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "pipeline/step_record.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <fstream>
#include <sstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

struct Shoot {
  const char* name;
  double sun[3];
  int seed;
  double zenith[3];
};

std::string spec(const Shoot& s) {
  std::ostringstream y;
  y << "rsibr_synth: 1\nseed: " << s.seed << "\n"
    << "environment: {pattern: sun_and_sky, size: 512, sun_direction: [" << s.sun[0] << ", " << s.sun[1] << ", "
    << s.sun[2] << "], sun_radius_deg: 0.6, sun_rgb: [5.0e5, 4.75e5, 4.25e5], zenith_rgb: [" << s.zenith[0] << ", "
    << s.zenith[1] << ", " << s.zenith[2] << "], horizon_rgb: [1.0, 0.95, 0.85]}\n"
    << "balls:\n  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.15, 1.3, 0]}\n"
    << "  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.15, 1.3, 0], albedo: [0.18, 0.18, 0.18]}\n"
    << "camera: {width: 320, height: 240, lens: {model: LENSMODEL_PINHOLE, focal_px: 700}, response: srgb, format: png, supersampling: 3}\n"
    << "exposure: {middle_s: 0.004, count: 7, step_ev: 2, iso: 100, aperture: 8}\n"
    << "views:\n  - {plan: ring, count: 3, elevation_deg: 10, distance_m: 1.0, azimuth0_deg: 0}\n"
    << "truth_map_size: 64\n";
  return y.str();
}

Vec3 integral3(const EnvMap& e) {
  const std::vector<double> v = integral(e);
  return Vec3(v[0], v[1], v[2]);
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class ClippedSun : public ::testing::TestWithParam<Shoot> {};

TEST_P(ClippedSun, TheProbeGetsTheSunBackAndCapturedMatchesComputed) {
  const Shoot& shoot = GetParam();
  const fs::path root =
      fs::temp_directory_path() / ("rsibr-clipped-" + std::string(shoot.name) + "-" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  const SynthScene scene = parse_synth_scene(spec(shoot), "clipped.yaml", root);
  write_synth_capture(scene, root / "syn");
  ProcessOptions o;
  o.photoset = (root / "syn" / "photos").string();
  o.out = root / "out";
  o.lens = (root / "syn" / "truth" / "camera.cameramodel").string();
  o.poses = (root / "syn" / "truth" / "truth.yaml").string();
  o.map_size = 64;
  o.turntable = 1;
  o.render_width = 32;
  o.render_height = 24;
  o.render_views_res = 8;
  const ProcessResult r = run_process(o);

  // The sun was clipped in every chrome view and recovered from the grey ball.
  const nlohmann::json& s = r.summary["sources"];
  ASSERT_EQ(s["regions"].size(), 1u) << s.dump();
  ASSERT_EQ(s["sources"].size(), 1u) << s.dump();
  const nlohmann::json& src = s["sources"][0];
  const Vec3 sun = Vec3(shoot.sun[0], shoot.sun[1], shoot.sun[2]).normalized();
  const Vec3 d(src["direction"][0].get<double>(), src["direction"][1].get<double>(), src["direction"][2].get<double>());
  const double angle = angle_between(d, sun) * 180 / kPi;
  EXPECT_LT(angle, 1.0);
  EXPECT_EQ(src["balls"][0], "grey");
  EXPECT_EQ(src["views"].size(), 3u);

  // The probe's integral per channel against the truth's (in the merge's unit: gain_normalised).
  const double unit =
      YAML::LoadFile((root / "syn" / "truth" / "truth.yaml").string())["camera"]["gain_normalised"].as<double>();
  const Vec3 truth = integral3(synth_environment(scene)) * unit;
  const Vec3 after = integral3(read_environment((o.out / "probe.exr").string()));
  const Vec3 before = integral3(read_environment((o.out / "probe-measured.exr").string()));
  std::printf("  %s: sun %.2f degrees off; probe integral %.3f %.3f %.3f of the truth (measured %.3f %.3f %.3f)\n",
              shoot.name, angle, after[0] / truth[0], after[1] / truth[1], after[2] / truth[2], before[0] / truth[0],
              before[1] / truth[1], before[2] / truth[2]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(after[k] / truth[k], 1.0, 0.10) << k;
    EXPECT_LT(before[k] / truth[k], 0.6) << k;
  }

  // Computed grey against the true grey maps and against the captured ones, after the gain fit.
  CompareOptions co;
  co.view_tolerance_deg = 1.0;
  const MapSet computed = read_map_set((o.out / "maps" / "computed-grey.exr").string());
  const MapSet captured = read_map_set((o.out / "maps" / "captured-grey.exr").string());
  const MapSet true_grey = read_map_set((root / "syn" / "truth" / "maps" / "grey.exr").string());
  const double vs_truth = compare_map_sets(computed, true_grey, co).after.relative_rms;
  const double vs_captured = r.summary["compare"]["balls"][0]["overall"]["after"]["relative_rms"].get<double>();
  std::printf("  %s: computed grey vs truth %.4f, captured vs computed %.4f\n", shoot.name, vs_truth, vs_captured);
  EXPECT_LT(vs_truth, 0.10);
  EXPECT_LT(vs_captured, 0.10);
  for (const double g : r.summary["compare"]["balls"][0]["fit"]["gains"]) EXPECT_NEAR(g, 1.0, 0.10);

  // The report says what was clipped and recovered; the probe's header lists the source.
  const std::string html = text_of(r.report);
  EXPECT_NE(html.find("Clipped light sources"), std::string::npos);
  EXPECT_NE(html.find("Clipped light:</b> the source at azimuth"), std::string::npos);
  EXPECT_NE(html.find("of the light"), std::string::npos);
  const EnvMap probe = read_environment((o.out / "probe.exr").string());
  ASSERT_TRUE(probe.attributes.count("lightSources"));
  EXPECT_EQ(nlohmann::json::parse(probe.attributes.at("lightSources")).size(), 1u);

  // --no-sources: the measured probe with the sun at its lower bound (far below the truth), the
  // report says recovery was off, and the grey ball is far off.
  o.recover_sources = false;
  const ProcessResult off = run_process(o);
  const Vec3 unrecovered = integral3(read_environment((o.out / "probe.exr").string()));
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(unrecovered[k], before[k] * (1 - 1e-6)) << k;
    EXPECT_LT(unrecovered[k] / truth[k], 0.7) << k;
  }
  EXPECT_GT(off.summary["compare"]["balls"][0]["overall"]["after"]["relative_rms"].get<double>(), 3 * vs_captured);
  const std::string html_off = text_of(off.report);
  EXPECT_NE(html_off.find("Recovery was off"), std::string::npos);
  EXPECT_NE(html_off.find("only a lower bound"), std::string::npos);
  fs::remove_all(root);
}

INSTANTIATE_TEST_SUITE_P(Shoots, ClippedSun,
                         ::testing::Values(Shoot{"high", {0.3, 0.85, 0.45}, 5, {0.25, 0.45, 1.0}},
                                           Shoot{"low", {-0.6, 0.35, -0.7}, 6, {0.35, 0.5, 0.9}}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace rsibr
