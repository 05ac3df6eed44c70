// calib/lens/far_camera.h: crops of the ball. The crop test and the far lens's bound at their exact
// values; a view placed on a larger canvas keeps its pixels, gains no edge and flags what it
// added; and a rendered chrome ball cropped as people crop them (the ball filling the frame, cut
// by one edge) is found and taken as the crop's ball.
#include "calib/lens/far_camera.h"
#include "core/test_data.h"  // tests/core/test_data.h

#include "calib/balls/ball_identification.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "calib_cases.h"
#include "hdr/merge.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

TEST(FarCamera, FillsFrameExactlyAtTheCropFraction) {
  // Diameter / shorter side = 0.6 exactly fills; a hair less does not; the longer side is irrelevant.
  EXPECT_TRUE(fills_frame(0.3 * 500, 500, 800));
  EXPECT_FALSE(fills_frame(0.3 * 500 - 1e-9, 500, 800));
  EXPECT_TRUE(fills_frame(0.3 * 500, 800, 500));
  EXPECT_FALSE(fills_frame(std::nan(""), 500, 500));
  EXPECT_FALSE(fills_frame(200, 0, 500));
}

TEST(FarCamera, LensCoversTheLargestViewAndKeepsEveryBallNearlyOrthographic) {
  const LensModel lens = far_camera_lens({{493, 493}, {493, 494}, {480, 500}});
  EXPECT_EQ(lens.width(), 493);
  EXPECT_EQ(lens.height(), 500);
  const double f = lens.intrinsics().at(0);
  EXPECT_DOUBLE_EQ(f, kFarCameraFocalPerSide * 500);
  // The largest ball a view can hold (radius half the long side) subtends under 0.29 degrees.
  EXPECT_LT(std::asin(250.0 / f) / kDeg, 0.29);
  EXPECT_THROW(far_camera_lens({}), std::invalid_argument);
  EXPECT_THROW(far_camera_lens({{0, 10}}), std::invalid_argument);
}

TEST(FarCamera, IsRecognisedAfterAWriteAndReadAndOtherLensesAreNot) {
  const LensModel far = far_camera_lens({{493, 493}, {493, 494}});
  EXPECT_TRUE(is_far_camera(far));
  testing::TempDir dir;
  const auto file = dir.path() / "far.cameramodel";
  far.write(file);
  EXPECT_TRUE(is_far_camera(LensModel::read(file)));
  EXPECT_FALSE(is_far_camera(LensModel::pinhole(0.99 * kFarCameraFocalPerSide * 494, 493, 494)));
  EXPECT_FALSE(is_far_camera(LensModel::pinhole(700, 640, 480)));
  EXPECT_FALSE(is_far_camera(LensModel("LENSMODEL_OPENCV4", {49400, 49400, 246, 246.5, 0, 0, 0, 0}, 493, 494)));
}

TEST(FarCamera, CanvasKeepsThePhotoReplicatesItsBorderAndFlagsTheRest) {
  ViewImage v;
  v.radiance = cv::Mat(3, 4, CV_32FC3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) v.radiance.at<cv::Vec3f>(y, x) = cv::Vec3f(float(x), float(y), 1.f);
  v.flags = cv::Mat::zeros(3, 4, CV_8UC1);
  v.flags.at<unsigned char>(1, 1) = kClipped;
  const LensModel lens = LensModel::pinhole(1000, 6, 5);
  const ViewImage c = on_lens_canvas(v, lens, "v");
  ASSERT_EQ(c.radiance.cols, 6);
  ASSERT_EQ(c.radiance.rows, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      const bool photo = x < 4 && y < 3;
      const cv::Vec3f want(float(std::min(x, 3)), float(std::min(y, 2)), 1.f);  // replicated: no step
      EXPECT_EQ(c.radiance.at<cv::Vec3f>(y, x), want) << x << "," << y;
      const unsigned char f = c.flags.at<unsigned char>(y, x);
      EXPECT_EQ((f & kOutside) != 0, !photo) << x << "," << y;
    }
  EXPECT_EQ(c.flags.at<unsigned char>(1, 1), kClipped);
  // A view of the lens's size is returned as it is; a larger one is an error naming it.
  EXPECT_EQ(on_lens_canvas(c, lens, "v").radiance.data, c.radiance.data);
  try {
    on_lens_canvas(v, LensModel::pinhole(1000, 3, 5), "north");
    FAIL() << "a view wider than the lens was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("north: 4x3 is larger"), std::string::npos) << e.what();
  }
}

// A chrome ball rendered through a long lens and cropped the way people crop them: the ball
// fills the crop (diameter about 95% of its side) and the right edge cuts 10 px off it. The finder
// must locate it (it touches or leaves the frame, where Hough sees little of its outline) and take
// it as the crop's one listed ball; on a larger canvas (another view's size) the far camera must
// extract it with nothing read from the padding where the cut part of the ball would be.
TEST(FarCamera, ACropOfARenderedChromeBallIsFoundAndExtractedOnACanvas) {
  const LensModel full = LensModel::pinhole(1200, 480, 360);
  const testing::RenderedView rv = testing::render_view(testing::rig_scene(full, 1.0, false));
  const Vec3 centre = testing::ball_centre_cam(rv, 0);
  const double r_px = full.intrinsics().at(0) * std::tan(std::asin(0.05 / centre.norm()));
  const Vec2 c = full.project(centre);
  const int side = int(std::lround(2 * r_px / 0.95)), cut = 10;
  const int x0 = int(std::lround(c.x() + r_px)) - cut - side, y0 = int(std::lround(c.y() - side / 2.0));
  ASSERT_GE(x0, 0);
  ASSERT_GE(y0, 0);
  ASSERT_LE(x0 + side, rv.radiance.cols);
  ASSERT_LE(y0 + side, rv.radiance.rows);
  const cv::Mat crop = rv.radiance(cv::Rect(x0, y0, side, side)).clone();
  const Vec2 truth = c - Vec2(x0, y0);

  const LensModel lens = far_camera_lens({{side, side}, {side + 2 * cut, side + 3}});
  ViewImage view;
  view.radiance = crop;
  view = on_lens_canvas(view, lens, "crop");
  const ViewCandidates vc = view_candidates(view.radiance, lens, {{"chrome", BallKind::chrome, 0.1}});
  ASSERT_GE(vc.pick.at(0), 0) << "the crop's ball was not taken";
  const BallCandidate& b = vc.cands.at(std::size_t(vc.pick[0]));
  EXPECT_LT((b.loc.centre_px - truth).norm(), 0.01 * r_px);
  EXPECT_NEAR(b.loc.radius_px, r_px, 0.01 * r_px);

  ExtractOptions eo;
  eo.size = 64;
  eo.mirror = true;
  const MapView mv = extract_sphere_map(view.radiance, view.flags, lens, b.loc.fit.cone, Mat3::Identity(), eo);
  // Texel (x, y) of the disc shows the ball point of normal (x, y, z), at pixel centre + r (x, -y)
  // in the near-orthographic far camera: those beyond the crop's right edge (with a pixel's
  // margin for the bilinear taps) are unseen; none is NaN; most of the disc is seen.
  const double edge = (side - 0.5 - truth.x() + 1.5) / r_px;
  int seen = 0, disc = 0, beyond = 0;
  for (int y = 0; y < mv.rgb.rows; ++y)
    for (int x = 0; x < mv.rgb.cols; ++x) {
      const cv::Vec3f p = mv.rgb.at<cv::Vec3f>(y, x);
      ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
      const Vec2 d((x + 0.5) / 32 - 1, 1 - (y + 0.5) / 32);
      if (d.squaredNorm() >= 1) continue;
      ++disc;
      seen += mv.confidence.at<float>(y, x) > 0;
      if (d.x() > edge) {
        ++beyond;
        EXPECT_EQ(mv.confidence.at<float>(y, x), 0.f) << x << "," << y;
      }
    }
  EXPECT_GT(beyond, 10);
  EXPECT_GT(seen, disc / 2);
}

}  // namespace
}  // namespace rsibr
