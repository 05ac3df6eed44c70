// The sources step (pipeline/light_sources_step.h) and the report's account of it
// (pipeline/light_sources_report.h) on small captured maps with a sun clipped in every view
// (tests/lights/clipped_shoot.h), and on maps where nothing is clipped: the step writes the probe
// with the source in its header, the report's warning names the source and the share of the light
// it holds, and appears only when something was clipped.
#include "pipeline/light_sources_report.h"
#include "pipeline/light_sources_step.h"

#include "lights/clipped_shoot.h"

#include <gtest/gtest.h>

#include <unistd.h>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

struct StepRun {
  nlohmann::json summary;
  fs::path dir;
};

StepRun run_step_on(const EnvMap& env, double clip, const std::string& name, bool recover = true) {
  const testing::ClippedShoot shoot = testing::clipped_shoot(env, clip, 4, 10, 15, 0.005, 32);
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
  EXPECT_NE(warning.find("missing from the probe"), std::string::npos) << warning;
  EXPECT_NE(light_sources_section(r.dir, r.summary).find("Recovery was off"), std::string::npos);
  fs::remove_all(r.dir);
}

}  // namespace
}  // namespace rsibr
