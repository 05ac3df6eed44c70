// capture/synth_capture.h and the scene spec: determinism, what the folders hold, strict specs.
#include "capture/synth_capture.h"

#include "capture/camera_poses.h"
#include "capture/camera_response.h"
#include "core/lensfun_lens.h"
#include "formats/photo_set.h"
#include "formats/truth_image.h"
#include "formats/map_set.h"
#include "core/test_data.h"
#include "synth_cases.h"
#include "formats/image_codecs.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <tbb/global_control.h>
#include <opencv2/imgproc.hpp>

#include <fstream>
#include <map>
#include <sstream>

namespace rsibr {
namespace {
namespace fs = std::filesystem;

std::map<std::string, std::string> folder_bytes(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    out[fs::relative(e.path(), root).string()] = ss.str();
  }
  return out;
}

TEST(SynthCapture, SameSeedGivesSameBytes) {
  testing::TempDir dir;
  SynthScene scene = testing::small_scene(", response: measured, vignetting: 0.3",
                                          "chessboards: {count: 1, corners: 4, spacing_m: 0.01}\n");
  write_synth_capture(scene, dir.path() / "a");
  write_synth_capture(scene, dir.path() / "b");
  scene.seed = 8;
  write_synth_capture(scene, dir.path() / "c");
  const auto a = folder_bytes(dir.path() / "a"), b = folder_bytes(dir.path() / "b"), c = folder_bytes(dir.path() / "c");
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) EXPECT_TRUE(b.at(name) == bytes) << name;
  EXPECT_FALSE(a.at("photos/view00/view00_b01.png") == c.at("photos/view00/view00_b01.png"));
}

TEST(SynthCapture, BytesDoNotDependOnTheThreadCount) {
  testing::TempDir dir;
  const SynthScene scene = testing::small_scene(", vignetting: 0.2");
  write_synth_capture(scene, dir.path() / "many");
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    write_synth_capture(scene, dir.path() / "one");
  }
  const auto a = folder_bytes(dir.path() / "many"), b = folder_bytes(dir.path() / "one");
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) EXPECT_TRUE(b.at(name) == bytes) << name;
}

TEST(SynthCapture, PhotoSetLoadsBackWithExposuresAndTruth) {
  testing::TempDir dir;
  const SynthScene scene = testing::small_scene(", format: tiff");
  const SynthReport r = write_synth_capture(scene, dir.path() / "out");
  EXPECT_EQ(r.views, 2);
  EXPECT_EQ(r.brackets, 6);
  const PhotoSet set = load_photo_set(dir.path() / "out" / "photos");
  ASSERT_EQ(set.views.size(), 2u);
  ASSERT_EQ(set.balls.size(), 2u);
  EXPECT_EQ(set.balls[1].kind, BallKind::grey);
  const auto& br = set.views[1].brackets;
  ASSERT_EQ(br.size(), 3u);
  EXPECT_DOUBLE_EQ(*br[0].exposure_s, 0.0025);
  EXPECT_DOUBLE_EQ(*br[2].exposure_s, 0.04);
  EXPECT_DOUBLE_EQ(*br[1].relative_exposure(), 0.01 / 64);
  const cv::Mat tif = rsibr::read_image(br[2].file.string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(tif.depth(), CV_16U);
  EXPECT_EQ(tif.cols, 96);
  const fs::path truth = dir.path() / "out" / "truth";
  const LensModel lens = LensModel::read(truth / "camera.cameramodel");
  EXPECT_TRUE(lens == scene.camera.lens);
  const MapSet chrome = read_map_set((truth / "maps" / "chrome.exr").string());
  ASSERT_EQ(chrome.views.size(), 2u);
  EXPECT_EQ(chrome.width(), 16);
  // The map's view points from the ball centre to the camera centre.
  const auto poses = plan_camera_poses(scene);
  EXPECT_LT((chrome.views[1].view - (poses[1].eye - scene.balls[0].centre).normalized()).norm(), 1e-6);
  const cv::Mat L = read_truth_image(truth / "views" / "view01_radiance.exr");
  EXPECT_EQ(L.cols, 96);
  EXPECT_TRUE(cv::checkRange(L, true, nullptr, 0, 1e30));
  const YAML::Node ty = YAML::LoadFile((truth / "truth.yaml").string());
  EXPECT_DOUBLE_EQ(ty["camera"]["gain"].as<double>(), r.gain);
  EXPECT_DOUBLE_EQ(ty["camera"]["gain_normalised"].as<double>(), r.gain / scene.camera.full_well);
  EXPECT_EQ(ty["views"].size(), 2u);
  EXPECT_EQ(ty["views"][1]["brackets"].size(), 3u);
  std::ifstream csv(truth / "response.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "code,R,G,B");
}

// The merge convention: the middle bracket's mean code inverts (through the response table) to
// about L e k / full_well on average where nothing clips.
TEST(SynthCapture, CodesInvertToRadianceTimesExposureTimesGain) {
  testing::TempDir dir;
  const SynthScene scene = testing::small_scene(", response: srgb, format: tiff, read_noise: 0");
  const SynthReport r = write_synth_capture(scene, dir.path() / "out");
  const fs::path out = dir.path() / "out";
  const cv::Mat L = read_truth_image(out / "truth" / "views" / "view00_radiance.exr");
  cv::Mat codes = rsibr::read_image((out / "photos" / "view00" / "view00_b01.tif").string(), cv::IMREAD_UNCHANGED);
  cv::cvtColor(codes, codes, cv::COLOR_BGR2RGB);
  const CameraResponse srgb("srgb");
  const double e = 0.01 / 64;
  double sum_ratio = 0;
  int n = 0;
  for (int y = 0; y < L.rows; ++y)
    for (int x = 0; x < L.cols; ++x)
      for (int k = 0; k < 3; ++k) {
        const double code = codes.at<cv::Vec3w>(y, x)[k];
        if (code >= 65535 || code < 1000) continue;
        const double X = srgb.relative(code / 65535.0, k) * scene.camera.full_well;
        sum_ratio += X / (L.at<cv::Vec3f>(y, x)[k] * e * r.gain);
        ++n;
      }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(sum_ratio / n, 1.0, 0.01);
}

TEST(SynthCapture, RefusesANonEmptyOutputAndLeavesNothingOnError) {
  testing::TempDir dir;
  fs::create_directories(dir.path() / "full");
  std::ofstream(dir.path() / "full" / "x") << "x";
  EXPECT_THROW(write_synth_capture(testing::small_scene(), dir.path() / "full"), std::invalid_argument);
  // A ball name the spec would refuse (a scene built in code): its map file is refused inside the
  // truth folder, after the photos were written.
  SynthScene bad = testing::small_scene();
  bad.balls[1].name = "no/such/folder";
  EXPECT_THROW(write_synth_capture(bad, dir.path() / "new"), std::invalid_argument);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"full"});
  // A camera inside a ball is refused before any work.
  SynthScene inside = testing::small_scene();
  inside.views[0].distance_m = 0.02;
  inside.views[0].look_at = inside.balls[0].centre;
  EXPECT_THROW(write_synth_capture(inside, dir.path() / "inside"), std::invalid_argument);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"full"});
}

TEST(SynthScene, UnknownKeysAndBadValuesNameTheirPath) {
  auto error_of = [](const std::string& text) {
    try {
      parse_synth_scene(text, "s.yaml", ".");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(testing::small_scene_text(", colour: 3")).find("scene.camera.colour: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(testing::small_scene_text(", vignetting: 1.5")).find("scene.camera.vignetting"),
            std::string::npos);
  EXPECT_NE(error_of(testing::small_scene_text(", response: gamma")).find("scene.camera.response"), std::string::npos);
  EXPECT_NE(
      error_of(testing::small_scene_text("", "chessboards: {count: -1}\n")).find("s.yaml: scene.chessboards.count"),
      std::string::npos);
  const std::string bad_name = testing::small_scene_text();
  EXPECT_NE(error_of(std::string(bad_name).replace(bad_name.find("name: grey"), 10, "name: a/b")).find("balls[1].name"),
            std::string::npos);
  EXPECT_NE(
      error_of(std::string(bad_name).replace(bad_name.find("name: grey, kind: grey"), 22, "name: grey, kind: glossy"))
          .find("balls[1].albedo: glossy balls take a brdf"),
      std::string::npos);
  EXPECT_NE(error_of("rsibr_synth: 2\n").find("rsibr_synth"), std::string::npos);
}

// `lens: {model: lensfun, ...}` is the database's profile (core/lensfun_lens.h) of the named lens
// on the named camera; the photos' EXIF then carries its nominal focal length, and the camera
// vignettes as the profile says at the exposure's aperture unless the spec gives a vignetting.
TEST(SynthScene, ALensfunLensIsTheDatabasesProfileWithItsVignetting) {
  auto with_lens = [](const std::string& lens, const std::string& extra = "") {
    std::string text = testing::small_scene_text(
        ", make: Canon, name: Canon EOS 600D, lens_name: Canon EF-S 18-55mm f/3.5-5.6 IS" + extra);
    const std::string pinhole = "lens: {model: LENSMODEL_PINHOLE, focal_px: 200}";
    return text.replace(text.find(pinhole), pinhole.size(), "lens: " + lens);
  };
  const SynthScene s = parse_synth_scene(with_lens("{model: lensfun, focal_mm: 18}"), "s.yaml", ".");
  const auto L = lensfun_lens("Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 96, 72);
  ASSERT_TRUE(L);
  EXPECT_EQ(s.camera.lens.name(), L->lens.name());
  EXPECT_EQ(s.camera.lens.intrinsics(), L->lens.intrinsics());
  EXPECT_EQ(s.camera.exif_focal_mm, 18);
  const auto v = lensfun_vignetting("Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 8, 96, 72);
  ASSERT_TRUE(v && s.camera.vignetting_poly);
  for (int i = 0; i < 3; ++i) EXPECT_EQ((*s.camera.vignetting_poly)[i], v->k[std::size_t(i)]);
  EXPECT_LT(v->k[0], 0) << "the EF-S 18-55mm darkens toward the corners at 18 mm";
  // A given vignetting wins; the profile may name another lens than the EXIF does.
  const SynthScene g =
      parse_synth_scene(with_lens("{model: lensfun, focal_mm: 18}", ", vignetting: 0.1"), "s.yaml", ".");
  EXPECT_FALSE(g.camera.vignetting_poly);
  const SynthScene other = parse_synth_scene(
      with_lens("{model: lensfun, focal_mm: 18, lens: Canon EF-S 18-55mm f/3.5-5.6 IS}"), "s.yaml", ".");
  EXPECT_EQ(other.camera.lens.intrinsics(), L->lens.intrinsics());
  auto error_of = [&](const std::string& lens) {
    try {
      parse_synth_scene(with_lens(lens), "s.yaml", ".");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("{model: lensfun}").find("focal_mm"), std::string::npos) << error_of("{model: lensfun}");
  EXPECT_NE(error_of("{model: lensfun, focal_mm: 18, focal_px: 300}").find("not with model: lensfun"),
            std::string::npos);
  EXPECT_NE(error_of("{model: LENSMODEL_PINHOLE, focal_px: 200, focal_mm: 18}").find("only with model: lensfun"),
            std::string::npos);
  EXPECT_NE(error_of("{model: lensfun, focal_mm: 18, lens: Acme Wonderlens}").find("does not know the lens"),
            std::string::npos);
}

TEST(CameraPoses, RingCamerasSitAtTheDistanceAndLookAtTheTarget) {
  SynthScene scene = testing::small_scene();
  scene.views = {SynthViewPlan{}, SynthViewPlan{}};
  scene.views[0].plan = "ring";
  scene.views[0].count = 4;
  scene.views[0].elevation_deg = 20;
  scene.views[1].plan = "handheld";
  scene.views[1].count = 3;
  const auto poses = plan_camera_poses(scene);
  ASSERT_EQ(poses.size(), 7u);
  const Vec3 at = scene.rig_centre();
  for (int i = 0; i < 4; ++i) {
    const CameraPose& p = poses[std::size_t(i)];
    EXPECT_NEAR((p.eye - at).norm(), 1.5, 1e-12);
    EXPECT_NEAR(std::asin((p.eye - at).y() / 1.5) * 180 / kPi, 20, 1e-9);
    EXPECT_NEAR(p.world_from_cam.col(2).dot((at - p.eye).normalized()), 1, 1e-12);
    EXPECT_NEAR(p.world_from_cam.determinant(), 1, 1e-12);
    EXPECT_LT(p.world_from_cam.col(1).y(), 0);  // image down is world down
  }
  EXPECT_NEAR(poses[1].eye.x() - at.x(), 1.5 * std::cos(20 * kPi / 180), 1e-12);  // azimuth 90: +X
  for (int i = 4; i < 7; ++i) {
    EXPECT_NEAR(poses[std::size_t(i)].world_from_cam.determinant(), 1, 1e-12);
    EXPECT_GT((poses[std::size_t(i)].eye - at).norm(), 1.3);
  }
  const auto again = plan_camera_poses(scene);
  EXPECT_EQ(again[5].eye, poses[5].eye);
}

// Pan turns a camera aimed down about the world's vertical: the target moves left and the horizon
// stays level (x stays horizontal); yaw turns it about its own y axis, which tilts the horizon.
TEST(CameraPoses, PanKeepsTheHorizonLevelWhereYawTiltsIt) {
  SynthScene scene = testing::small_scene();
  SynthViewPlan p;
  p.plan = "ring";
  p.count = 1;
  p.elevation_deg = 25;
  scene.views = {p, p, p};
  scene.views[1].pan_deg = 15;
  scene.views[2].yaw_deg = 15;
  const auto poses = plan_camera_poses(scene);
  const Vec3 at = scene.rig_centre();
  for (int i : {1, 2}) {
    const Vec3 target = poses[std::size_t(i)].world_from_cam.transpose() * (at - poses[std::size_t(i)].eye);
    EXPECT_LT(target.x(), -0.2 * target.z()) << i << ": the target moves left";
  }
  EXPECT_LT(std::abs(poses[1].world_from_cam.col(0).y()), 1e-12);
  EXPECT_GT(std::abs(poses[2].world_from_cam.col(0).y()), 0.05);
  EXPECT_NEAR(poses[1].world_from_cam.col(2).y(), poses[0].world_from_cam.col(2).y(),
              1e-12);  // still aimed down as much
}

}  // namespace
}  // namespace rsibr
