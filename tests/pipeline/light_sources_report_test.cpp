// The sources step (pipeline/light_sources_step.h) and the report's account of it
// (pipeline/light_sources_report.h) on small captured maps with a sun clipped in every view
// (tests/lights/clipped_shoot.h), and on maps where nothing is clipped: the step writes the probe
// with the source in its header, the report's warning names the source and the share of the light
// it holds, and appears only when something was clipped.
#include "pipeline/light_sources_report.h"
#include "pipeline/light_sources_step.h"

#include "calib/probe/probe.h"
#include "formats/exr_file.h"
#include "lights/clipped_shoot.h"

#include <gtest/gtest.h>

#include <unistd.h>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

struct ProbeChannels {
  cv::Mat rgb, confidence, flags;
};

ProbeChannels read_probe_channels(const fs::path& path) {
  const ExrFileIn file(path.string());
  ProbeChannels p;
  p.rgb = file.read(0, {"R", "G", "B"});
  p.confidence = file.read(0, {"confidence"});
  p.flags = file.read(0, {"flags"});
  return p;
}

struct StepRun {
  nlohmann::json summary;
  fs::path dir;
};

StepRun run_step_on(const EnvMap& env, double clip, const std::string& name, bool recover = true, int views = 4) {
  const testing::ClippedShoot shoot = testing::clipped_shoot(env, clip, views, 10, 15, 0.005, 32);
  const fs::path dir = fs::temp_directory_path() / ("rsibr-sources-step-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_map_set((dir / "chrome.exr").string(), shoot.chrome);
  write_map_set((dir / "grey.exr").string(), shoot.grey);
  write_environment((dir / "probe-measured.exr").string(), testing::shoot_probe(shoot, 128).env);
  LightSourcesStep s;
  s.chrome = {dir / "chrome.exr"};
  s.grey = {{"grey", dir / "grey.exr"}};
  s.measured = dir / "probe-measured.exr";
  s.out = dir / "probe.exr";
  s.probe_width = 128;
  s.chrome_fresnel = testing::kChrome;
  s.recover = recover;
  return {run_light_sources_step(s), dir};
}

TEST(LightSourcesStep, AClippedSunIsWrittenIntoTheProbeAndTheReportNamesIt) {
  const Vec3 sun = testing::direction_at(30, 40);
  const EnvMap env = testing::environment_with(std::nullopt, {{sun, 0.5, Vec3(2e4, 2e4, 1.8e4)}}, 128);
  const StepRun r = run_step_on(env, 50, "sun");
  ASSERT_EQ(r.summary["sources"].size(), 1u) << r.summary.dump();
  const EnvMap probe = read_environment((r.dir / "probe.exr").string());
  ASSERT_TRUE(probe.attributes.count("lightSources"));
  const nlohmann::json listed = nlohmann::json::parse(probe.attributes.at("lightSources"));
  ASSERT_EQ(listed.size(), 1u);
  for (const char* key : {"direction", "solid_angle_sr", "radiance", "power", "power_sigma", "views", "balls"})
    EXPECT_TRUE(listed[0].contains(key)) << key;
  EXPECT_EQ(listed[0]["views"].size(), 4u);
  // The probe's integral grows by the recovered power.
  const std::vector<double> before = integral(read_environment((r.dir / "probe-measured.exr").string()));
  const std::vector<double> after = integral(probe);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(after[std::size_t(k)] - before[std::size_t(k)],
                r.summary["recovered_power"][std::size_t(k)].get<double>(), 1e-4 * after[std::size_t(k)]);
  const std::string warning = light_sources_warning(r.summary);
  EXPECT_NE(warning.find("the source at azimuth"), std::string::npos) << warning;
  EXPECT_NE(warning.find("of the light"), std::string::npos) << warning;
  EXPECT_NE(warning.find("grey"), std::string::npos) << warning;
  const std::string section = light_sources_section(r.dir, r.summary);
  EXPECT_NE(section.find("Clipped light sources"), std::string::npos);
  EXPECT_NE(section.find("data:image/png;base64,"),
            std::string::npos);  // the probe around the source, before and after
  EXPECT_EQ(section.find("nan"), std::string::npos);
  fs::remove_all(r.dir);
}

TEST(LightSourcesStep, NothingClippedGivesNoWarningAndTheMeasuredProbe) {
  const EnvMap env =
      testing::environment_with(std::nullopt, {{testing::direction_at(30, 40), 0.5, Vec3(2e4, 2e4, 1.8e4)}}, 128);
  const StepRun r = run_step_on(env, 1e12, "none");
  EXPECT_TRUE(r.summary["regions"].empty());
  EXPECT_EQ(light_sources_warning(r.summary), "");
  EXPECT_EQ(light_sources_section(r.dir, r.summary), "");
  // The step's probe is the chrome maps' blend as read back (frames stored as float), unchanged.
  const EnvMap a = read_environment((r.dir / "probe.exr").string()),
               b = read_environment((r.dir / "probe-measured.exr").string());
  EXPECT_LT(cv::norm(a.pixels, b.pixels, cv::NORM_INF), 1e-6 * cv::norm(b.pixels, cv::NORM_INF));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(r.summary["recovered_power"][std::size_t(k)].get<double>(), 0.0);
  EXPECT_FALSE(a.attributes.count("lightSources"));
  fs::remove_all(r.dir);
}

TEST(LightSourcesStep, WithRecoveryOffTheReportSaysWhatIsMissing) {
  const EnvMap env =
      testing::environment_with(std::nullopt, {{testing::direction_at(30, 40), 0.5, Vec3(2e4, 2e4, 1.8e4)}}, 128);
  const StepRun r = run_step_on(env, 50, "off", false);
  ASSERT_EQ(r.summary["regions"].size(), 1u);
  EXPECT_TRUE(r.summary["sources"].empty());
  const std::string warning = light_sources_warning(r.summary);
  EXPECT_NE(warning.find("was not recovered"), std::string::npos) << warning;
  EXPECT_NE(warning.find("only a lower bound"), std::string::npos) << warning;
  EXPECT_NE(light_sources_section(r.dir, r.summary).find("Recovery was off"), std::string::npos);
  // The sun's texels keep their lower bound, flagged, with no confidence: the probe holds more
  // light than the trusted texels alone.
  const ProbeChannels p = read_probe_channels(r.dir / "probe.exr");
  int bound = 0;
  for (int y = 0; y < p.flags.rows; ++y)
    for (int x = 0; x < p.flags.cols; ++x)
      if (int(p.flags.at<float>(y, x)) == kProbeLowerBound) {
        ++bound;
        EXPECT_EQ(p.confidence.at<float>(y, x), 0.0f);
        EXPECT_GT(p.rgb.at<cv::Vec3f>(y, x)[1], 40.0f);  // at least the clip level, Fresnel divided out
      }
  EXPECT_GT(bound, 0);
  const std::vector<double> before = integral(read_environment((r.dir / "probe-measured.exr").string()));
  const std::vector<double> after = integral(read_environment((r.dir / "probe.exr").string()));
  for (int k = 0; k < 3; ++k) EXPECT_GT(after[std::size_t(k)], 1.05 * before[std::size_t(k)]) << k;
  fs::remove_all(r.dir);
}

TEST(LightSourcesStep, DirectionsNoViewSawAreFilledFlaggedAndWithoutConfidence) {
  const EnvMap env =
      testing::environment_with(std::nullopt, {{testing::direction_at(30, 40), 0.5, Vec3(2e4, 2e4, 1.8e4)}}, 128);
  const StepRun r = run_step_on(env, 1e12, "fill", true, 1);  // one view: the cone behind the ball is unseen
  EXPECT_GT(r.summary["filled_fraction"].get<double>(), 0.005);
  const ProbeChannels p = read_probe_channels(r.dir / "probe.exr");
  const EnvMap measured = read_environment((r.dir / "probe-measured.exr").string());
  int filled = 0;
  for (int y = 0; y < p.flags.rows; ++y)
    for (int x = 0; x < p.flags.cols; ++x) {
      const cv::Vec3f v = p.rgb.at<cv::Vec3f>(y, x);
      if (int(p.flags.at<float>(y, x)) == kProbeFilled) {
        ++filled;
        ASSERT_EQ(p.confidence.at<float>(y, x), 0.0f);
        for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(v[k]) && v[k] > 0) << y << " " << x;
      } else if (p.confidence.at<float>(y, x) > 0) {
        const cv::Vec3f m = measured.pixels.at<cv::Vec3f>(y, x);  // what was seen stays as seen
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(v[k], m[k], 1e-5 * (1 + m[k])) << y << " " << x;
      }
    }
  EXPECT_GT(filled, 0);
  fs::remove_all(r.dir);
}

}  // namespace
}  // namespace rsibr
