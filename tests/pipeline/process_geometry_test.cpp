// rsibr process on a shoot built to break the geometry around the orientation: handheld cameras
// aimed 25 degrees down (the first camera is not level), background circles (a uniform disc, a
// ringed target, an unlisted grey sphere), strong vignetting (1.3 stops at the corner) with one view
// turned so the grey ball sits toward a corner, one view turned so the frame cuts the grey ball.
// Orientations solved, lens given (the chessboards still serve the vignetting). The photographer is
// left out of the scene, so that restoring his light (on by default, calib/extraction/occluded_light.h) is
// checked to change little where there is none; bench/geometry_robustness.py measures shoots with
// one.
// Checked against the truth: no wrong ball, the cut ball flagged, the world level within 1 degree,
// the vignetting, the grey maps within 0.1 stop per view after the gain fit.
#include "pipeline/process_pipeline.h"

#include "calib/orientation/pose_file.h"
#include "capture/synth_capture.h"
#include "capture/synth_scene.h"
#include "compare/map_compare.h"
#include "formats/map_set.h"
#include "hdr/vignetting.h"
#include "pipeline/pose_input.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <fstream>
#include <sstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

const fs::path kLobby = fs::path(RSIBR_CACHE_DIR) / "assets/hdri/lobby.exr";

SynthScene shoot() {
  const std::string text = R"(
rsibr_synth: 1
seed: 21
environment: {file: )" + kLobby.string() +
                           R"(, sanitize: true}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1, centre: [-0.07, 1.3, 0]}
  - {name: grey, kind: grey, diameter_m: 0.1, centre: [0.07, 1.3, 0]}
stand: true
photographer: false
clutter:
  - {shape: disc, centre: [0.5, 1.5, -3.0], radius_m: 0.2, albedo: [0.6, 0.6, 0.6]}
  - {shape: disc, centre: [-1.0, 1.7, -2.6], radius_m: 0.35, rings: 3, albedo: [0.9, 0.9, 0.85], ring_albedo: [0.1, 0.1, 0.1]}
  - {shape: sphere, centre: [-0.5, 1.2, -1.5], radius_m: 0.12, albedo: [0.3, 0.3, 0.3]}
  - {shape: disc, centre: [2.4, 1.6, 1.0], radius_m: 0.3, rings: 2, albedo: [0.8, 0.8, 0.8], ring_albedo: [0.2, 0.2, 0.25]}
camera:
  width: 480
  height: 360
  lens: {model: LENSMODEL_OPENCV4, focal_px: 620, distortion: [-0.05, 0.01, 0.0, 0.0]}
  response: srgb
  vignetting: [-0.5, -0.1, 0.0]
exposure: {middle_s: 0.05, count: 5, step_ev: 2, iso: 400, aperture: 5.6}
views:
  - {plan: handheld, count: 6, elevation_deg: 25, distance_m: 0.55, jitter_m: 0.01, jitter_deg: 1.0}
  - {plan: ring, azimuths_deg: [100], elevation_deg: 20, distance_m: 0.55, look_at: [0, 1.42, 0], pan_deg: 14}
  - {plan: ring, azimuths_deg: [250], elevation_deg: 15, distance_m: 0.55, pan_deg: 18}
chessboards: {count: 6, corners: 10, spacing_m: 0.02}
truth_map_size: 48
)";
  return parse_synth_scene(text, "geometry.yaml", ".");
}

class ProcessGeometry : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kLobby)) return;
    root_ = fs::temp_directory_path() / ("rsibr-process-geometry-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    scene_ = new SynthScene(shoot());
    write_synth_capture(*scene_, root_ / "syn");
    ProcessOptions o;
    o.photoset = (root_ / "syn" / "photos").string();
    o.out = root_ / "out";
    o.lens = (root_ / "syn" / "truth" / "camera.cameramodel").string();
    o.chrome_fresnel = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}";
    o.map_size = 48;
    o.probe_width = 128;
    o.bake_samples = 64;
    o.turntable = 1;
    o.render_width = 32;
    o.render_height = 24;
    o.render_views_res = 8;
    result_ = new ProcessResult(run_process(o));
    options_ = new ProcessOptions(o);
    truth_ = new PoseSet(read_given_poses((root_ / "syn" / "truth" / "truth.yaml").string()));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete options_;
    delete scene_;
    delete truth_;
    if (!root_.empty()) fs::remove_all(root_);
  }
  void SetUp() override {
    if (!fs::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  }
  // The truth's pixel of a ball's centre in a view, and whether the frame cuts its disc.
  static Vec2 truth_px(const std::string& view, int ball, double* radius_px) {
    const YAML::Node t = YAML::LoadFile((root_ / "syn" / "truth" / "truth.yaml").string());
    for (const auto& v : t["views"])
      if (v["name"].as<std::string>() == view) {
        const auto b = v["balls"][ball];
        const double d = b["distance_m"].as<double>();
        *radius_px = 620 * 0.05 / std::sqrt(d * d - 0.05 * 0.05);
        return Vec2(b["centre_px"][0].as<double>(), b["centre_px"][1].as<double>());
      }
    return Vec2::Zero();
  }
  static fs::path root_;
  static SynthScene* scene_;
  static ProcessResult* result_;
  static PoseSet* truth_;
  static ProcessOptions* options_;
};

fs::path ProcessGeometry::root_;
SynthScene* ProcessGeometry::scene_ = nullptr;
ProcessResult* ProcessGeometry::result_ = nullptr;
PoseSet* ProcessGeometry::truth_ = nullptr;
ProcessOptions* ProcessGeometry::options_ = nullptr;

// Every view oriented and extracted; every ball found is the true ball (within a fifth of its
// radius); the grey ball is found in every view where it shows (the cut one flagged) and the
// background circles never.
TEST_F(ProcessGeometry, NoWrongBallIsAcceptedAndTheCutBallIsFlagged) {
  const auto& ex = result_->summary["extract"]["views"];
  ASSERT_EQ(ex.size(), 8u);
  int found = 0, cut = 0;
  for (const auto& v : ex) {
    ASSERT_FALSE(v.contains("left_out")) << v["name"];
    for (std::size_t b = 0; b < 2; ++b) {
      const auto& f = v["balls"][b];
      double r = 0;
      const Vec2 truth = truth_px(v["name"], int(b), &r);
      if (!f.contains("centre_px")) {
        ADD_FAILURE() << v["name"] << " " << f["ball"] << " missing: " << f["note"];
        continue;
      }
      ++found;
      const Vec2 c(f["centre_px"][0].get<double>(), f["centre_px"][1].get<double>());
      EXPECT_LT((c - truth).norm(), 0.2 * r) << v["name"] << " " << f["ball"];
      const bool truly_cut = truth.x() - r < 0 || truth.y() - r < 0 || truth.x() + r > 479 || truth.y() + r > 359;
      EXPECT_EQ(f["cut"].get<bool>(), truly_cut) << v["name"] << " " << f["ball"];
      cut += truly_cut;
    }
  }
  EXPECT_EQ(found, 16);
  EXPECT_GE(cut, 1) << "the shoot must cut a ball";
}

// The estimated world up against the truth: the levelled world's +Y is the true up within 1
// degree (the first camera, aimed 25 degrees down, would tilt it by that), within 3 sigmas.
TEST_F(ProcessGeometry, TheProbeIsLevelWithinADegree) {
  const PoseSet est = read_pose_file((root_ / "out" / "poses.yaml").string());
  EXPECT_EQ(est.gauge, "estimated-up");
  Vec3 up = Vec3::Zero();
  for (const ViewPose& v : est.views)
    up += truth_->find(v.name)->world_from_cam * v.world_from_cam.transpose() * Vec3(0, 1, 0);
  const double tilt = angle_between(up, Vec3(0, 1, 0)) * 180 / kPi;
  const double sigma = result_->summary["orient"]["world_up"]["sigma_deg"].get<double>();
  std::printf("  probe tilt %.3f degrees (sigma %.3f), the first camera's %.1f\n", tilt, sigma,
              result_->summary["orient"]["world_up"]["tilt_from_first_camera_deg"].get<double>());
  EXPECT_LT(tilt, 1.0);
  EXPECT_LT(tilt, 3 * sigma + 0.05);
  EXPECT_GT(result_->summary["orient"]["world_up"]["tilt_from_first_camera_deg"].get<double>(), 15.0);
}

// The rig check behind the world-up estimate: every view is checked (its grey ball found, the cut
// one included), and on a shoot whose views are all well oriented none is left out of the estimate.
TEST_F(ProcessGeometry, EveryViewIsCheckedAgainstTheRigAndNoneIsLeftOut) {
  const auto& solve = result_->summary["orient"]["solve"];
  const auto d = solve["rig_disagreement_radii"].get<std::vector<double>>();
  ASSERT_EQ(d.size(), 8u);
  for (double x : d) {
    EXPECT_GE(x, 0.0) << "a view was not checked";
    EXPECT_LT(x, 0.25);
  }
  EXPECT_TRUE(solve["left_out_of_up"].empty()) << solve["left_out_of_up"];
}

// The vignetting estimated from the chessboards: the corner's fall-off within 0.1 stop of the truth.
TEST_F(ProcessGeometry, TheVignettingIsEstimatedAndReported) {
  const auto& v = result_->summary["hdr"]["vignetting"];
  ASSERT_TRUE(v.contains("estimate")) << v.dump();
  Vignetting truth = Vignetting::none(480, 360, Vec2(239.5, 179.5));
  truth.k = {-0.5, -0.1, 0.0};
  EXPECT_NEAR(v["model"]["corner_stops"].get<double>(), truth.corner_stops(), 0.1);
  EXPECT_EQ(v["model"]["source"], "chessboards");
  EXPECT_TRUE(fs::is_regular_file(root_ / "out" / "hdr" / "vignetting.json"));
}

// A run's grey maps (moved into the truth's world through each view's true rotation) against the
// true ones, after the global gain fit: at least 7 views paired, each within 0.1 stop (log RMS).
void expect_grey_within_a_tenth_of_a_stop(const fs::path& run, const fs::path& truth_maps, const PoseSet& truth) {
  const PoseSet est = read_pose_file((run / "poses.yaml").string());
  MapSet grey = read_map_set((run / "maps" / "captured-grey.exr").string());
  for (MapView& v : grey.views) {
    const std::string img = v.image;
    v.world_from_view = truth.find(img)->world_from_cam * est.find(img)->world_from_cam.transpose() * v.world_from_view;
    v.view = v.world_from_view.col(2);
  }
  CompareOptions co;
  co.view_tolerance_deg = 2;
  const Comparison c = compare_map_sets(grey, read_map_set((truth_maps / "grey.exr").string()), co);
  ASSERT_GE(c.pairs.size(), 7u);
  for (const PairComparison& p : c.pairs) {
    std::printf("  %s: %.3f stops\n", grey.views[p.index_a].image.c_str(), p.after.log_rms_stops);
    EXPECT_LT(p.after.log_rms_stops, 0.1) << grey.views[p.index_a].image;
  }
}

// The captured grey maps against the true ones: within 0.1 stop in every view, the corner one included.
TEST_F(ProcessGeometry, GreyMapsAreWithinATenthOfAStopOfTheTruthInEveryView) {
  expect_grey_within_a_tenth_of_a_stop(root_ / "out", root_ / "syn" / "truth" / "maps", *truth_);
}

// The photographer's light is restored by default; on a shoot without a photographer the capsule
// behind each camera holds the environment, which the view's chrome ball sees as the probe does,
// so little is restored (and the grey maps are within 0.1 stop of the truth, above).
TEST_F(ProcessGeometry, ByDefaultThePhotographersLightIsRestoredAndWhereThereIsNoneLittleChanges) {
  int restored = 0;
  for (const auto& v : result_->summary["extract"]["views"])
    for (const auto& b : v["balls"])
      if (b.contains("occluder_light")) {
        ++restored;
        EXPECT_TRUE(b["occluder_light"]["photographer"].get<bool>()) << v["name"];
        EXPECT_LT(b["occluder_light"]["mean_stops"].get<double>(), 0.05) << v["name"];
      }
  EXPECT_GE(restored, 7);
  for (const MapView& v : read_map_set((root_ / "out" / "maps" / "captured-grey.exr").string()).views)
    EXPECT_NE(v.attributes.count("occluderLight"), 0u) << v.image;
}

// --no-occluder-light: the grey maps as photographed, with no restoration recorded. The steps before
// extract are reused.
TEST_F(ProcessGeometry, WithoutRestorationTheGreyMapsAreAsPhotographed) {
  fs::copy(root_ / "out", root_ / "out-as-photographed", fs::copy_options::recursive);
  ProcessOptions o = *options_;
  o.out = root_ / "out-as-photographed";
  o.occluder_light = false;
  const ProcessResult r = run_process(o);
  for (const auto& v : r.summary["extract"]["views"])
    for (const auto& b : v["balls"]) EXPECT_FALSE(b.contains("occluder_light")) << v["name"];
  for (const MapView& v : read_map_set((o.out / "maps" / "captured-grey.exr").string()).views)
    EXPECT_EQ(v.attributes.count("occluderLight"), 0u) << v.image;
  expect_grey_within_a_tenth_of_a_stop(o.out, root_ / "syn" / "truth" / "maps", *truth_);
}

// Each view's mask is in the report.
TEST_F(ProcessGeometry, EachViewsMaskIsInTheReport) {
  std::ifstream in(result_->report);
  std::stringstream s;
  s << in.rdbuf();
  const std::string html = s.str();
  EXPECT_NE(html.find("<h3>Masks</h3>"), std::string::npos);
  for (const auto& v : result_->summary["extract"]["views"])
    EXPECT_TRUE(fs::is_regular_file(root_ / "out" / "masks" / (v["name"].get<std::string>() + ".png"))) << v["name"];
  EXPECT_NE(html.find("Vignetting"), std::string::npos);
  EXPECT_NE(html.find("World up estimated"), std::string::npos);
}

}  // namespace
}  // namespace rsibr
