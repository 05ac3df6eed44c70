// core/lens_model.h: mrcal lens models, .cameramodel files, the ray table.
#include "core/lens_model.h"

#include "core/test_data.h"  // tests/core/test_data.h

#include <gtest/gtest.h>

#include <fstream>

namespace rsibr {
namespace {

// A strongly distorted OPENCV8 lens (k1 = -0.15: about 8% barrel distortion at the corners).
LensModel wide_opencv8() {
  return LensModel("LENSMODEL_OPENCV8", {900, 905, 639.5, 479.5, -0.15, 0.04, 0.0005, -0.0003, 0.0, 0.02, 0.0, 0.01},
                   1280, 960);
}

std::vector<LensModel> models() {
  return {LensModel::pinhole(800, 640, 480), wide_opencv8(),
          LensModel("LENSMODEL_OPENCV4", {700, 700, 320, 240, 0.1, -0.05, 0.001, 0.002}, 640, 480),
          LensModel("LENSMODEL_STEREOGRAPHIC", {400, 400, 319.5, 239.5}, 640, 480)};
}

TEST(LensModel, ProjectUnprojectRoundTripsEveryModel) {
  for (const LensModel& lens : models()) {
    double worst = 0;
    for (int r = 0; r <= 10; ++r)
      for (int c = 0; c <= 10; ++c) {
        const Vec2 p(-0.5 + c * lens.width() / 10.0, -0.5 + r * lens.height() / 10.0);
        const Vec3 d = lens.unproject(p);
        EXPECT_NEAR(d.norm(), 1.0, 1e-12);
        worst = std::max(worst, (lens.project(d) - p).norm());
        // Projection is scale invariant: any point along the ray lands on the same pixel.
        worst = std::max(worst, (lens.project(3.7 * d) - p).norm());
      }
    EXPECT_LT(worst, 1e-6) << lens.name();
  }
}

TEST(LensModel, PinholeProjectsLikeTheFormula) {
  const LensModel lens = LensModel::pinhole(500, 640, 360);
  const Vec2 p = lens.project(Vec3(0.2, -0.1, 2.0));
  EXPECT_NEAR(p.x(), 500 * 0.1 + 319.5, 1e-12);
  EXPECT_NEAR(p.y(), -500 * 0.05 + 179.5, 1e-12);
}

TEST(LensModel, WrittenFileReadsBackIdentical) {
  testing::TempDir dir;
  for (LensModel lens : models()) {
    lens.set_rt_cam_ref({0.1, -0.2, 0.3, 1.5, -2.25, 1e-3});
    const auto file = dir.path() / "m.cameramodel";
    lens.write(file);
    const LensModel back = LensModel::read(file);
    EXPECT_EQ(back.name(), lens.name());
    EXPECT_EQ(back.width(), lens.width());
    EXPECT_EQ(back.height(), lens.height());
    EXPECT_EQ(back.intrinsics(), lens.intrinsics()) << lens.name();
    EXPECT_EQ(back.rt_cam_ref(), lens.rt_cam_ref()) << lens.name();
  }
}

// A splined stereographic model (100 degrees across, zero spline), as mrcal writes one.
std::string splined_text() {
  std::string zeros;
  for (int i = 0; i < 2 * 5 * 4; ++i) zeros += ", 0";
  return "{ 'lensmodel': 'LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=5_Ny=4_fov_x_deg=100',"
         "  'intrinsics': [ 500, 500, 319.5, 239.5" +
         zeros + " ], 'imagersize': [ 640, 480 ], 'extrinsics': [0,0,0,0,0,0] }";
}

TEST(LensModel, ReadsSplinedModelText) {
  const std::string text = splined_text();
  const LensModel lens = LensModel::parse(text);
  EXPECT_EQ(lens.name(), "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=5_Ny=4_fov_x_deg=100");
  EXPECT_EQ(lens.intrinsics().size(), 4u + 40u);
  EXPECT_TRUE(lens.can_project_behind_camera());
  const Vec2 p(100.25, 400.5);
  EXPECT_LT((lens.project(lens.unproject(p)) - p).norm(), 1e-6);
}

TEST(LensModel, BadInputIsAnErrorNamingTheProblem) {
  EXPECT_THROW(LensModel("LENSMODEL_NOPE", {1, 1, 1, 1}, 10, 10), std::invalid_argument);
  EXPECT_THROW(LensModel("LENSMODEL_OPENCV8", {1, 1, 1, 1}, 10, 10), std::invalid_argument);
  EXPECT_THROW(LensModel::pinhole(std::nan(""), 10, 10), std::invalid_argument);
  EXPECT_THROW(LensModel::pinhole(100, 0, 10), std::invalid_argument);
  testing::TempDir dir;
  const auto bad = dir.path() / "bad.cameramodel";
  std::ofstream(bad) << "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1, 2] }";
  try {
    LensModel::read(bad);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
  }
}

TEST(LensModel, MalformedTextsThatMrcalReadsPastTheirEndAreRefusedBeforeMrcalSeesThem) {
  // Found by fuzz/fuzz_camera_model (fuzz/regressions/): mrcal 2.2's parser read past the end of
  // these and crashed; they are refused with the line at fault.
  const std::pair<std::string, std::string> cases[] = {
      {"{\n    'lensmodel':  'LENSMODEL_PINHOLE',\n    'intrinsics': [ 100, 100, 47.5, 31.5 ],\n"
       "    'imagersize': [ 96, 64 ],\n    'extrinsic 0, 0, 0, 0, 0 ],\n# generated for the",
       "line 5: a string that spans lines"},
      {"# a comment\n{\n    'lensmodel':  'LENSMODEL_OPENCV8',\n    'intrinsics':# comment  [ 7t0",
       "line 4: expected a number"},
      {"{ 'lensmodel': 'LENSMODEL_PINHOLE', # x", "expected a quoted key"},
      {"{ 'lensmodel': 'LENSMODEL_PINHOLE' } trailing", "text after the closing '}'"},
      {"{ 'a': [[[[[1]]]]] }", "nested too deep"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      LensModel::parse(text, "m.cameramodel");
      FAIL() << "no error for: " << text;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("m.cameramodel: not a valid mrcal .cameramodel (", 0), 0u) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(LensModel, CommentsAnywhereAreIgnoredEvenWithQuotesAndNoFinalNewline) {
  // Found by fuzz/fuzz_camera_model: mrcal 2.2 crashed on a well-formed model whose last line was a
  // comment holding a quote, with no newline after it. Comments are now blanked before mrcal reads.
  const std::string text =
      "# it's a model\n{\n    'lensmodel':  'LENSMODEL_PINHOLE', # the 'core' only\n"
      "    'intrinsics': [ 100, 101, 47.5, 31.5 ],\n    'imagersize': [ 96, 64 ],\n"
      "    'extrinsics': [ 0, 0, 0, 0, 0, 0 ],\n}\n#e'";
  const LensModel lens = LensModel::parse(text, "m.cameramodel");
  EXPECT_EQ(lens.name(), "LENSMODEL_PINHOLE");
  ASSERT_EQ(lens.intrinsics().size(), 4u);
  EXPECT_EQ(lens.intrinsics()[1], 101.0);
  EXPECT_EQ(lens.width(), 96);
  EXPECT_EQ(lens.height(), 64);
}

TEST(RayTable, InterpolatedRaysReprojectToTheirPixels) {
  for (const LensModel& lens : {LensModel::pinhole(800, 640, 480), wide_opencv8()}) {
    const RayTable table(lens, 8);
    double worst = 0;
    for (double y = -0.5; y <= lens.height() - 0.5; y += 7.31)
      for (double x = -0.5; x <= lens.width() - 0.5; x += 5.17) {
        const Vec3 d = table.direction(x, y);
        EXPECT_NEAR(d.norm(), 1.0, 1e-12);
        worst = std::max(worst, (lens.project(d) - Vec2(x, y)).norm());
      }
    EXPECT_LT(worst, 1e-3) << lens.name();
  }
}

// A table over a part of the image (a ball's box), at step 4 as the ball identification makes
// one: its rays reproject to their pixels, for a model that can see behind the camera too (the
// whole-image table refuses it), and a box reaching behind the camera is refused.
TEST(RayTable, ATableOverAPartReprojectsAndWorksForEveryModel) {
  const LensModel fisheye = LensModel::parse(splined_text());
  EXPECT_THROW(RayTable(fisheye, 8), std::invalid_argument);
  for (const LensModel& lens : {wide_opencv8(), fisheye}) {
    const Vec2 lo(430.3, 20.7), hi(611.9, 190.2);  // a corner, where the distortion is strongest
    const RayTable table(lens, 4, lo, hi);
    double worst = 0;
    for (double y = lo.y(); y <= hi.y(); y += 1.37)
      for (double x = lo.x(); x <= hi.x(); x += 1.13)
        worst = std::max(worst, (lens.project(table.direction(x, y)) - Vec2(x, y)).norm());
    EXPECT_LT(worst, 1e-4) << lens.name();
  }
  // 20000 px from the centre of a stereographic lens of focal length 500 px is 174 degrees off
  // its axis: behind the camera.
  EXPECT_THROW(RayTable(fisheye, 4, Vec2(-20000, 200), Vec2(-19900, 300)), std::invalid_argument);
  EXPECT_THROW(RayTable(fisheye, 4, Vec2(10, 10), Vec2(5, 20)), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
