// The lens step (pipeline/lens_step.h) on the cases that need no ball: a measured lens passes
// through byte for byte in its intrinsics, a metadata lens with nothing to refine it keeps its
// focal length and says why, and a lens with no focal length at all is an error naming --lens;
// crops of a rendered ball as the balls step (calib/balls/shoot_balls.h) finds them (the far
// camera, views of other sizes, a ghosted ball stopping the balls step).
#include "pipeline/lens_step.h"

#include "calib/balls/ball_candidates_picture.h"

#include "calib/calib_cases.h"
#include "calib/lens/far_camera.h"
#include "formats/image_codecs.h"
#include "core/test_data.h"
#include "hdr/merge.h"
#include "hdr/merged_exr.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

LensStep step_with(const testing::TempDir& dir, const std::string& source, double sigma) {
  const LensModel lens("LENSMODEL_OPENCV4", {410, 412, 159.5, 119.5, -0.1, 0.02, 0, 0}, 320, 240);
  lens.write(dir.path() / "camera.cameramodel");
  LensStep s;
  s.calibrated = dir.path() / "camera.cameramodel";
  s.source = source;
  s.prior_sigma_relative = sigma;
  s.out = dir.path() / "lens.cameramodel";
  return s;
}

TEST(LensStep, AMeasuredLensPassesThroughUnchanged) {
  testing::TempDir dir;
  const LensStep s = step_with(dir, "chessboards", 0);
  const nlohmann::json j = run_lens_step(s);
  EXPECT_FALSE(j["refined"].get<bool>());
  EXPECT_NE(j["why"].get<std::string>().find("measured"), std::string::npos) << j.dump();
  EXPECT_EQ(LensModel::read(s.out).intrinsics(), LensModel::read(s.calibrated).intrinsics());
  EXPECT_EQ(LensModel::read(s.out).name(), "LENSMODEL_OPENCV4");
}

TEST(LensStep, AMetadataLensWithNoBallOutlineKeepsItsFocalLengthAndSaysWhy) {
  testing::TempDir dir;
  const LensStep s = step_with(dir, "exif", 0.036);
  const nlohmann::json j = run_lens_step(s);
  EXPECT_FALSE(j["refined"].get<bool>());
  EXPECT_NE(j["why"].get<std::string>().find("no ball outline"), std::string::npos) << j.dump();
  EXPECT_DOUBLE_EQ(j["prior_sigma_px"].get<double>(), 0.036 * 410);
  EXPECT_EQ(LensModel::read(s.out).intrinsics(), LensModel::read(s.calibrated).intrinsics());
  LensStep off = step_with(dir, "lensfun", 0.03);
  off.refine = false;
  EXPECT_NE(run_lens_step(off)["why"].get<std::string>().find("--no-self-calibration"), std::string::npos);
}

TEST(LensStep, NoFocalLengthAndNoOutlineIsAnErrorNamingTheWayOut) {
  testing::TempDir dir;
  LensStep s = step_with(dir, "outlines", 0);
  for (bool refine : {true, false}) {
    s.refine = refine;
    try {
      run_lens_step(s);
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--lens FILE"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("no focal length"), std::string::npos) << e.what();
    }
  }
}

// Crops of one rendered chrome ball (the far-camera model, calib/lens/far_camera.h): views of different
// sizes whose ball fills the frame get one far pinhole on the largest view's canvas, whatever the
// metadata said; views of different sizes whose ball does not fill the frame are an error naming
// their sizes; a ball whose pixels the brackets disagree on stops the step.
namespace crops {

struct Shoot {
  cv::Mat radiance;  // the whole rendered frame
  Vec2 centre;       // the chrome ball's centre pixel in it
  double radius = 0;
};

const Shoot& shoot() {
  static const Shoot s = [] {
    const LensModel full = LensModel::pinhole(1200, 480, 360);
    const testing::RenderedView rv = testing::render_view(testing::rig_scene(full, 1.0, false));
    const Vec3 c = testing::ball_centre_cam(rv, 0);
    return Shoot{rv.radiance, full.project(c), 1200 * std::tan(std::asin(0.05 / c.norm()))};
  }();
  return s;
}

// A square window of `side` px centred on the ball, written as a merged view with a share `ghost`
// of the ball's disc flagged kGhost (spread evenly over it).
std::filesystem::path view(const testing::TempDir& dir, const std::string& name, int side, double ghost = 0) {
  const Shoot& s = shoot();
  const int x0 = int(std::lround(s.centre.x() - side / 2.0)), y0 = int(std::lround(s.centre.y() - side / 2.0));
  MergedImage m;
  m.radiance = s.radiance(cv::Rect(x0, y0, side, side)).clone();
  m.variance = cv::Mat::zeros(side, side, CV_32FC3);
  m.flags = cv::Mat::zeros(side, side, CV_8UC1);
  const Vec2 c = s.centre - Vec2(x0, y0);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x)
      if ((Vec2(x, y) - c).norm() < s.radius && (x + 7 * y) % 100 < 100 * ghost) m.flags.at<uchar>(y, x) = kGhost;
  const std::filesystem::path p = dir.path() / (name + ".exr");
  write_merged_exr(p.string(), m, {{"view", name}});
  return p;
}

// The balls of views a and b as the balls step finds them through the step's calibrated lens
// (their candidates pictures in `pictures` when given).
ShootBalls found_balls(const testing::TempDir& dir, double ghost, int side_a, int side_b,
                       const std::filesystem::path& pictures = {}) {
  const std::vector<std::filesystem::path> files = {view(dir, "a", side_a, ghost), view(dir, "b", side_b)};
  ShootBallsInput in;
  in.views = {"a", "b"};
  in.read_view = [files](std::size_t v) { return read_view_image(files[v].string()); };
  in.lens = LensModel::read(dir.path() / "camera.cameramodel");
  in.listed = {{"chrome", BallKind::chrome, 0.1}};
  if (!pictures.empty())
    in.seen = [&](std::size_t v, const cv::Mat& radiance, const ViewCandidates& vc) {
      std::filesystem::create_directories(pictures);
      write_ball_candidates_picture(pictures / (in.views[v] + ".png"), radiance, vc);
    };
  return find_shoot_balls(in);
}

LensStep two_views(const testing::TempDir& dir, int side_a, int side_b, const std::filesystem::path& pictures = {}) {
  LensStep s = step_with(dir, "exif", 0.036);
  s.balls = found_balls(dir, 0, side_a, side_b, pictures);
  s.pictures = pictures;
  return s;
}

}  // namespace crops

TEST(LensStep, CropsOfTheBallGetTheFarCameraOnTheLargestViewsCanvas) {
  testing::TempDir dir;
  const double r = crops::shoot().radius;
  const int a = int(std::lround(2 * r / 0.9)), b = a + 7;  // the ball fills 90% and 88% of the frames
  const LensStep s = crops::two_views(dir, a, b);
  const nlohmann::json j = run_lens_step(s);
  EXPECT_TRUE(j["far_camera"].get<bool>()) << j.dump();
  const LensModel lens = LensModel::read(s.out);
  EXPECT_EQ(lens.name(), "LENSMODEL_PINHOLE");
  EXPECT_EQ(lens.width(), b);
  EXPECT_EQ(lens.height(), b);
  EXPECT_DOUBLE_EQ(lens.intrinsics().at(0), kFarCameraFocalPerSide * b);
  EXPECT_LT(j["ball_half_angle_deg"].get<double>(), 0.29);
  for (const auto& v : j["views"]) EXPECT_NEAR(v["ball_radius_px"].get<double>(), r, 0.02 * r) << v.dump();
}

TEST(LensStep, ViewsOfDifferentSizesThatAreNotCropsAreAnErrorNamingThem) {
  testing::TempDir dir;
  const int a = int(std::lround(crops::shoot().radius * 3.5));  // the ball fills 57%: no crop
  const LensStep s = crops::two_views(dir, a, a + 1, dir.path() / "balls");
  try {
    run_lens_step(s);
    FAIL() << "views of two sizes were given one lens";
  } catch (const std::invalid_argument& e) {
    const std::string want = "the views differ in size (a " + std::to_string(a) + "x" + std::to_string(a) + ", b " +
                             std::to_string(a + 1) + "x" + std::to_string(a + 1) + ")";
    EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    // The error points at the pictures of the candidates, which a failed step leaves behind.
    EXPECT_NE(std::string(e.what()).find("circled and numbered in balls/VIEW.png"), std::string::npos) << e.what();
  }
  for (const char* view : {"a", "b"}) {
    const cv::Mat png = read_image((s.pictures / (std::string(view) + ".png")).string());
    EXPECT_FALSE(png.empty()) << view;
  }
}

TEST(BallsStep, ABallTheBracketsDisagreeOnStopsTheStepButAFewGhostPixelsDoNot) {
  testing::TempDir dir;
  step_with(dir, "exif", 0.036);
  const int a = int(std::lround(2 * crops::shoot().radius / 0.9));
  EXPECT_NO_THROW(crops::found_balls(dir, 0.01, a, a));  // 1% of the disc: kept
  try {
    crops::found_balls(dir, 0.05, a, a);
    FAIL() << "a ghosted ball was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("view a: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("disagree between brackets"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rsibr
