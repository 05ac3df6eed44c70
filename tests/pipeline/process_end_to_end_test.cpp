// rsibr process end to end on datasets-synthetic/minimal-grey.yaml (a chrome and a grey ball, 3
// views, pinhole, 7 brackets): synthesized with its truth, processed once (calibration from the
// chessboards, the poses from the truth), then checked against the truth with stated errors.
// Thresholds are about twice the errors measured when they were set (release, seed 1):
//   captured grey vs computed from the probe, after the gain fit: 2.2% relative RMS, gain 1.07
//   captured grey vs the true grey maps: 3.4%; computed grey vs the true maps: 4.4%
//   probe vs the true environment (both area-resampled to 32 x 16 lat-long): 30%, 0.45 stops log RMS.
#include "pipeline/process_pipeline.h"

#include "calib/balls/balls_file.h"

#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "formats/exr_io.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "core/resample.h"
#include "calib/orientation/pose_file.h"
#include "pipeline/step_record.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

const char* kChromeFresnel = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}";

class ProcessEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("rsibr-process-e2e-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    scene_ = new SynthScene(load_synth_scene(fs::path(RSIBR_SOURCE_DIR) / "datasets-synthetic" / "minimal-grey.yaml"));
    write_synth_capture(*scene_, root_ / "syn");
    result_ = new ProcessResult(run_process(options()));
    probe_bytes_ = read_bytes(root_ / "out" / "probe.exr");
    computed_bytes_ = read_bytes(root_ / "out" / "maps" / "computed-grey.exr");
  }
  static std::string read_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void TearDownTestSuite() {
    delete result_;
    delete scene_;
    fs::remove_all(root_);
  }
  static ProcessOptions options() {
    ProcessOptions o;
    o.photoset = (root_ / "syn" / "photos").string();
    o.out = root_ / "out";
    o.poses = (root_ / "syn" / "truth" / "truth.yaml").string();
    o.chrome_fresnel = kChromeFresnel;
    o.map_size = 64;
    o.probe_width = 256;
    o.turntable = 2;
    o.render_width = 64;
    o.render_height = 48;
    o.render_views_res = 16;
    return o;
  }
  static MapSet maps(const std::string& name) { return read_map_set((root_ / "out" / "maps" / name).string()); }
  static MapSet truth(const std::string& ball) {
    return read_map_set((root_ / "syn" / "truth" / "maps" / (ball + ".exr")).string());
  }
  static fs::path root_;
  static SynthScene* scene_;
  static ProcessResult* result_;
  static std::string probe_bytes_, computed_bytes_;
};
std::string ProcessEndToEnd::probe_bytes_, ProcessEndToEnd::computed_bytes_;

fs::path ProcessEndToEnd::root_;
SynthScene* ProcessEndToEnd::scene_ = nullptr;
ProcessResult* ProcessEndToEnd::result_ = nullptr;

TEST_F(ProcessEndToEnd, EveryStepRanAndTheReportExists) {
  ASSERT_EQ(result_->steps.size(), process_steps().size());
  for (const StepOutcome& s : result_->steps) EXPECT_TRUE(s.ran) << s.step;
  EXPECT_TRUE(fs::is_regular_file(result_->report));
  EXPECT_EQ(result_->summary["calibrate"]["model"], "LENSMODEL_PINHOLE");
  EXPECT_NEAR(result_->summary["calibrate"]["intrinsics"][0].get<double>(), 700, 7);
}

TEST_F(ProcessEndToEnd, CapturedGreyMatchesComputedFromTheProbe) {
  CompareOptions o;
  const Comparison c = compare_map_sets(maps("captured-grey.exr"), maps("computed-grey.exr"), o);
  ASSERT_EQ(c.pairs.size(), 3u);
  EXPECT_LT(c.after.relative_rms, 0.05);
  ASSERT_TRUE(c.fit.has_value());
  for (double g : c.fit->gains) EXPECT_NEAR(g, 1.0, 0.15);  // the probe's level is the grey's: no calibration offset
  for (const PairComparison& p : c.pairs) {
    EXPECT_LT(p.angle_deg, 1e-3) << p.name;  // baked at the captured views
    EXPECT_TRUE(std::isfinite(p.after.relative_rms));
  }
}

TEST_F(ProcessEndToEnd, CapturedAndComputedGreyMatchTheTruth) {
  CompareOptions o;
  o.view_tolerance_deg = 1.0;  // the extracted view is the cone axis; the truth's the ball-to-camera ray
  const Comparison captured = compare_map_sets(maps("captured-grey.exr"), truth("grey"), o);
  const Comparison computed = compare_map_sets(maps("computed-grey.exr"), truth("grey"), o);
  EXPECT_LT(captured.after.relative_rms, 0.07);
  EXPECT_LT(computed.after.relative_rms, 0.09);
  for (const PairComparison& p : captured.pairs) EXPECT_LT(p.angle_deg, 0.5) << p.name;
}

TEST_F(ProcessEndToEnd, ProbeMatchesTheTrueEnvironment) {
  const EnvMap probe = read_environment((root_ / "out" / "probe.exr").string());
  const EnvMap env = synth_environment(*scene_);
  const Layout coarse(LayoutKind::LatLong, 32, 16);
  CompareOptions o;
  const Comparison c = compare_environments(resample(probe, coarse), resample(env, coarse), o);
  // Measured 0.30 and 0.45 stops: the sun spread over the 64-texel chrome maps' footprint and
  // the directions straight down (masked as the stand in every view, 0 in the probe) dominate.
  EXPECT_LT(c.after.relative_rms, 0.45);
  EXPECT_LT(c.after.log_rms_stops, 0.7);
  EXPECT_GT(result_->summary["probe"]["covered_fraction"].get<double>(), 0.95);
}

TEST_F(ProcessEndToEnd, ASecondRunSkipsEveryStep) {
  const ProcessResult again = run_process(options());
  for (const StepOutcome& s : again.steps) {
    EXPECT_FALSE(s.ran) << s.step << ": " << s.reason;
    EXPECT_GT(s.recorded_seconds, 0) << s.step;
  }
}

// A run folder copied elsewhere with new file times (cp -r) resumes: every step is up to date
// (paths relative to the run and photo folders, contents compared by SHA-256 where times differ).
TEST_F(ProcessEndToEnd, ACopiedRunFolderResumesWithoutRedoingAStep) {
  const fs::path copy = root_ / "copied" / "out";
  fs::create_directories(copy.parent_path());
  fs::copy(root_ / "out", copy, fs::copy_options::recursive);
  for (const auto& e : fs::recursive_directory_iterator(copy))
    if (e.is_regular_file()) fs::last_write_time(e.path(), fs::last_write_time(e.path()) + std::chrono::seconds(5));
  ProcessOptions o = options();
  o.out = copy;
  const ProcessResult again = run_process(o);
  for (const StepOutcome& s : again.steps) EXPECT_FALSE(s.ran) << s.step << ": " << s.reason;
  // The copy is a run of its own: a changed setting re-runs there, the original stays as it was.
  o.bake_samples = 96;
  const ProcessResult changed = run_process(o);
  std::map<std::string, bool> ran;
  for (const StepOutcome& s : changed.steps) ran[s.step] = s.ran;
  EXPECT_TRUE(ran["bake"]);
  EXPECT_FALSE(ran["extract"]);
  for (const StepOutcome& s : run_process(options()).steps) EXPECT_FALSE(s.ran) << s.step;
  // --ball VIEW:BALL=X,Y,R (a rough guess, 3 px and 10% off the truth) overrides that detection.
  const YAML::Node truth = YAML::LoadFile((root_ / "syn" / "truth" / "truth.yaml").string());
  const YAML::Node grey = truth["views"][1]["balls"][1];
  ASSERT_EQ(grey["name"].as<std::string>(), "grey");
  const double x = grey["centre_px"][0].as<double>(), y = grey["centre_px"][1].as<double>();
  const double r = 700 * 0.05 / grey["distance_m"].as<double>();
  o.ball_overrides = {"view01:grey=" + std::to_string(x + 3) + "," + std::to_string(y - 2) + "," +
                      std::to_string(1.1 * r)};
  const ProcessResult given = run_process(o);
  const auto& balls = given.summary["extract"]["views"][1]["balls"];
  EXPECT_EQ(balls[1]["status"], "given");
  EXPECT_LT(std::hypot(balls[1]["centre_px"][0].get<double>() - x, balls[1]["centre_px"][1].get<double>() - y), 1.0);
}

// Truth poses carry no balls: the orient step refines each view's chrome ball with the rotations
// held (or keeps the outline's where no features match), and poses.yaml carries them.
TEST_F(ProcessEndToEnd, PosesWithoutBallsGetTheirChromeBallsFromTheOrientStep) {
  const PoseSet p = read_pose_file((root_ / "out" / "poses.yaml").string());
  ASSERT_EQ(p.views.size(), 3u);
  for (const ViewPose& v : p.views) ASSERT_TRUE(v.ball.has_value()) << v.name;
  EXPECT_NE(result_->summary["orient"]["source"].get<std::string>().find("chrome balls refined"), std::string::npos);
  EXPECT_EQ(p.gauge, "up");  // the truth's world, kept
  // Every listed ball found in every view, where the truth puts it.
  for (const auto& v : result_->summary["extract"]["views"])
    for (const auto& b : v["balls"]) EXPECT_EQ(b["status"], "found") << v["name"] << " " << b["ball"];
}

TEST_F(ProcessEndToEnd, BallsAreFoundOnceAndTheLaterStepsReadThem) {
  // The balls step found every listed ball of every view; lens, orient and extract read its file.
  const ShootBalls found = read_balls_file(root_ / "out" / "balls.json");
  ASSERT_EQ(found.views.size(), 3u);
  for (const FoundView& v : found.views)
    for (std::size_t b = 0; b < found.listed.size(); ++b)
      EXPECT_EQ(v.balls[b].status, "found") << v.name << " " << found.listed[b].name;
  for (const char* step : {"lens", "orient", "extract"}) {
    const StepRecord r = read_step_record(root_ / "out", step);
    EXPECT_NE(std::find(r.inputs.begin(), r.inputs.end(), root_ / "out" / "balls.json"), r.inputs.end()) << step;
  }
  EXPECT_TRUE(fs::is_regular_file(root_ / "out" / "balls" / (found.views[0].name + ".png")));
  // Found again, the same file: the steps that read it find their inputs unchanged and stay.
  ProcessOptions o = options();
  o.force = {"balls"};
  const ProcessResult again = run_process(o);
  for (const StepOutcome& s : again.steps) EXPECT_EQ(s.ran, s.step == "balls" || s.step == "report") << s.step;
}

TEST_F(ProcessEndToEnd, ChangedSettingsRerunOnlyTheStepsAfterAndReproduceTheBytes) {
  ProcessOptions o = options();
  o.bake_samples = 96;  // the bake's setting: bake, compare and report re-run, not the merge
  const ProcessResult r = run_process(o);
  std::map<std::string, bool> ran;
  for (const StepOutcome& s : r.steps) ran[s.step] = s.ran;
  EXPECT_FALSE(ran["calibrate"]);
  EXPECT_FALSE(ran["hdr"]);
  EXPECT_FALSE(ran["extract"]);
  EXPECT_FALSE(ran["probe"]);
  EXPECT_TRUE(ran["bake"]);
  EXPECT_TRUE(ran["compare"]);
  EXPECT_FALSE(ran["render"]);
  EXPECT_TRUE(ran["report"]);
  o.force = {"hdr"};
  o.bake_samples = options().bake_samples;
  const ProcessResult forced = run_process(o);
  // hdr re-runs and writes the same bytes, so the steps after it find their inputs unchanged
  // (contents are compared, not times) and stay; bake and compare re-run for the samples set
  // back, the report for the records.
  for (const StepOutcome& s : forced.steps)
    EXPECT_EQ(s.ran, s.step == "hdr" || s.step == "bake" || s.step == "compare" || s.step == "report") << s.step;
  // Same inputs and seed, same bytes: re-run, the probe and the bake reproduce the first run's files.
  o.force = {"probe", "bake"};
  const ProcessResult again = run_process(o);
  for (const StepOutcome& s : again.steps)
    if (s.step == "probe" || s.step == "bake") {
      EXPECT_TRUE(s.ran) << s.step;
    }
  EXPECT_TRUE(read_bytes(root_ / "out" / "probe.exr") == probe_bytes_);
  EXPECT_TRUE(read_bytes(root_ / "out" / "maps" / "computed-grey.exr") == computed_bytes_);
  // Twice the albedo: the fitted gain doubles. The albedo scales the light recovered where every
  // view clipped it, which the restoration of the photographer's light reads: extract re-runs.
  o.force = {};
  o.grey_albedo = 2 * options().grey_albedo;
  const ProcessResult doubled = run_process(o);
  for (const StepOutcome& s : doubled.steps)
    if (s.step == "extract") EXPECT_TRUE(s.ran);
  const double g = doubled.summary["compare"]["balls"][0]["fit"]["gains"][1].get<double>();
  const double g0 = result_->summary["compare"]["balls"][0]["fit"]["gains"][1].get<double>();
  EXPECT_NEAR(g / g0, 2.0, 0.02);
}

TEST_F(ProcessEndToEnd, ReportIsSelfContained) {
  std::ifstream in(result_->report);
  std::stringstream text;
  text << in.rdbuf();
  const std::string html = text.str();
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  // No reference leaves the file: the only URL is the SVG namespace.
  std::size_t pos = 0, urls = 0;
  while ((pos = html.find("http", pos)) != std::string::npos) {
    EXPECT_EQ(html.compare(pos, 26, "http://www.w3.org/2000/svg"), 0) << html.substr(pos, 60);
    ++pos, ++urls;
  }
  EXPECT_EQ(html.find("src=\"file"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  for (const char* section :
       {"Camera response", "Orientations", "Light probe", "Captured vs computed", "Turntable", "Lens"})
    EXPECT_NE(html.find(section), std::string::npos) << section;
  // The turntable to orbit: the render step's page in a frame, escaped (no script runs in the
  // report itself; the page's data and code go with it).
  EXPECT_NE(html.find("<iframe class=\"viewer\""), std::string::npos);
  EXPECT_NE(html.find("&lt;script type=&quot;application/json&quot; id=&quot;rsibr-data&quot;&gt;"), std::string::npos);
  EXPECT_TRUE(fs::exists(result_->report.parent_path() / "render" / "viewer.html"));
}

// The orientation solve needs features the views share; the minimal sky has too few for views
// 120 degrees apart, so without --poses the run stops at the orient step with one message naming
// the view, rather than inventing poses, and writes no poses; the report up to that step says
// where it stopped and why (the error, the steps that ran, the failed step's record).
TEST_F(ProcessEndToEnd, WithoutSharedFeaturesTheOrientStepFailsClearly) {
  ProcessOptions o = options();
  o.poses.clear();
  o.out = root_ / "out-no-poses";
  try {
    run_process(o);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("orient"), std::string::npos) << what;
    EXPECT_NE(what.find("view"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(o.out / "poses.yaml"));
  EXPECT_TRUE(fs::exists(o.out / "steps" / "orient.failed.json"));
  ASSERT_TRUE(fs::exists(o.out / "report.html"));
  std::ifstream in(o.out / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(html.find("Stopped at orient"), std::string::npos);
  EXPECT_NE(html.find("<b>failed</b>"), std::string::npos);
  EXPECT_NE(html.find("Camera response"), std::string::npos) << "the steps before it are reported";
  EXPECT_EQ(html.find("Light probe"), std::string::npos) << "no step after it ran";
  EXPECT_TRUE(fs::exists(o.out / "hdr" / "view00.exr"));  // the steps before stay, for a resumed run
}

}  // namespace
}  // namespace rsibr
