// calib/extraction/sphere_map_extraction.h: extracted sphere maps against the true maps of capture/
// (compare/map_compare.h), the reflection solve against the law of reflection, the confidence channel.
#include "calib/extraction/sphere_map_extraction.h"

#include "calib/balls/ball_locator.h"
#include "calib_cases.h"
#include "capture/true_sphere_map.h"
#include "compare/map_compare.h"
#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

TEST(ReflectionNormal, SolutionObeysTheLawOfReflection) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g(0, 1);
  int solved = 0;
  for (int i = 0; i < 500; ++i) {
    const double dist = 1.5 + 20 * std::abs(g(rng));  // 1.5 to ~60 ball radii
    const Vec3 axis = (Vec3(0.2 * g(rng), 0.2 * g(rng), 1)).normalized();
    const Vec3 centre = axis * dist;
    const Mat3 cam_from_view = world_from_view_for(-axis, Vec3(0, -1, 0));
    // A disc point away from the rim (the map's mirror direction not near the singular one).
    Vec2 xy(g(rng), g(rng));
    xy *= 0.9 * std::abs(std::tanh(g(rng))) / xy.norm();
    const Vec3 r = cam_from_view * sphere_map::g_mirror(xy);
    const auto n = reflection_normal(centre, r, cam_from_view * sphere_map::g_normal(xy));
    ASSERT_TRUE(n.has_value()) << "distance " << dist;
    const Vec3 w = -(centre + *n).normalized();
    const Vec3 reflected = 2 * w.dot(*n) * *n - w;
    EXPECT_LT((reflected - r).norm(), 1e-9);
    EXPECT_GT(w.dot(*n), 0) << "the point faces the camera";
    ++solved;
  }
  EXPECT_EQ(solved, 500);
}

struct Extracted {
  ErrorMetrics exact, ortho;
  MapView map;
};

// One chrome (or grey) ball alone (nothing to occlude it), camera at `distance`, focal length
// scaled so the ball keeps radius_px; noise-free radiance; the ball located by calib/.
Extracted extract_against_truth(const std::string& kind, double distance, int size = 32, double radius_px = 60) {
  const double f = radius_px * distance / 0.05;
  const int w = static_cast<int>(3.2 * radius_px), h = static_cast<int>(2.6 * radius_px);
  SynthScene scene = testing::rig_scene(LensModel::pinhole(f, w, h), distance, false);
  std::vector<SynthBall> keep;
  for (const SynthBall& b : scene.balls)
    if (b.kind == kind) keep.push_back(b);
  scene.balls = keep;
  // No sun: the error measured is the geometry's, not the point sampling of the sun disc's edge
  // (a step of 500 times the sky) by the truth's texels.
  scene.environment.sun_rgb = Vec3::Zero();
  scene.views.front().look_at = keep.front().centre;
  const auto v = testing::render_view(scene);
  const LensModel& lens = scene.camera.lens;
  const Vec3 c = testing::ball_centre_cam(v, 0);
  const BallLocation loc =
      locate_ball(v.radiance, lens, {testing::ball_centre_px(v, 0) + Vec2(1, 1), 1.1 * f * 0.05 / c.norm()});
  MapSet truth;
  truth.views.push_back(true_sphere_map(keep.front(), v.pose.eye, v.env, size));
  Extracted out;
  for (const SphereIndexing mode : {SphereIndexing::reflection, SphereIndexing::orthographic}) {
    ExtractOptions opt;
    opt.size = size;
    opt.indexing = mode;
    opt.mirror = kind == "chrome";
    MapSet a;
    a.views.push_back(extract_sphere_map(v.radiance, {}, lens, loc.fit.cone, v.pose.world_from_cam, opt));
    CompareOptions co;
    co.fit = false;
    const Comparison cmp = compare_map_sets(a, truth, co);
    (mode == SphereIndexing::reflection ? out.exact : out.ortho) = cmp.before;
    if (mode == SphereIndexing::reflection) out.map = a.views.front();
  }
  return out;
}

// The exact reflection indexing reproduces the true chrome map (up to the Fresnel factor's angle,
// pixel interpolation and the ball's location) better than the orthographic one at close range.
TEST(SphereMapExtraction, ExactIndexingMatchesTheTrueChromeMap) {
  const Extracted e = extract_against_truth("chrome", 0.4);
  std::printf("  chrome at 0.4 m: relative RMS exact %.4f, orthographic %.4f; log RMS %.3f / %.3f stops\n",
              e.exact.relative_rms, e.ortho.relative_rms, e.exact.log_rms_stops, e.ortho.log_rms_stops);
  EXPECT_LT(e.exact.log_rms_stops, 0.03);
  EXPECT_LT(e.exact.relative_rms, 0.01);
  EXPECT_LT(e.exact.relative_rms, 0.5 * e.ortho.relative_rms);
  EXPECT_EQ(e.map.source, MapSource::Captured);
  EXPECT_EQ(e.map.warp, CentralDirection::Mirror);
}

// A Lambertian ball's radiance depends on the normal only: orthographic indexing is exact for it.
TEST(SphereMapExtraction, OrthographicIndexingMatchesTheTrueGreyMap) {
  const Extracted e = extract_against_truth("grey", 0.4);
  std::printf("  grey at 0.4 m: relative RMS orthographic %.4f (reflection indexing %.4f)\n", e.ortho.relative_rms,
              e.exact.relative_rms);
  EXPECT_LT(e.ortho.relative_rms, 0.01);
}

// The perspective error of orthographic indexing falls with the ball's distance D (the view
// direction varies by asin(R / D) across the ball), roughly in proportion; the exact indexing stays
// at the floor set by the ball's location and the resampling. Printed as a table (docs/calibration.md).
TEST(SphereMapExtraction, OrthographicErrorFallsWithDistanceExactStaysSmall) {
  std::printf("  | distance (m) | D/R | asin(R/D) (deg) | rel. RMS orthographic | rel. RMS exact |\n");
  double previous = 1e9;
  for (const double d : {0.25, 0.5, 1.0, 2.0}) {
    const Extracted e = extract_against_truth("chrome", d);
    std::printf("  | %.2f | %.0f | %.2f | %.4f | %.4f |\n", d, d / 0.05, std::asin(0.05 / d) * 180 / kPi,
                e.ortho.relative_rms, e.exact.relative_rms);
    EXPECT_LT(e.ortho.relative_rms, previous);
    EXPECT_LT(e.exact.relative_rms, 0.01);
    if (d <= 1.0) {
      EXPECT_LT(e.exact.relative_rms, e.ortho.relative_rms);
    }
    previous = e.ortho.relative_rms;
  }
}

TEST(SphereMapExtraction, ConfidenceIsZeroOutsideTheDiscOnClippedPixelsAndAtTheCamera) {
  const LensModel lens = LensModel::pinhole(300, 64, 64);
  cv::Mat img(64, 64, CV_32FC3, cv::Scalar::all(1.0));
  cv::Mat flags(64, 64, CV_8UC1, cv::Scalar(0));
  flags(cv::Rect(0, 0, 32, 64)).setTo(1);  // the left half clipped
  BallCone cone;
  cone.axis = Vec3(0, 0, 1);
  cone.half_angle = std::asin(0.1);
  ExtractOptions opt;
  opt.size = 16;
  opt.camera_mask_deg = 10;
  const MapView m = extract_sphere_map(img, flags, lens, cone, Mat3::Identity(), opt);
  int inside_right = 0;
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 16; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 16, 16);
      const float conf = m.confidence.at<float>(r, c);
      EXPECT_TRUE(conf >= 0 && conf <= 1);
      if (xy.norm() >= 1) {
        EXPECT_EQ(conf, 0) << "outside the disc";
      }
      // View x points to the image's right for an upright camera: the left half is clipped.
      if (xy.x() < -0.2) {
        EXPECT_EQ(conf, 0) << "clipped";
      }
      // The texel at the centre reflects the camera itself.
      if (xy.norm() < 0.05) {
        EXPECT_EQ(conf, 0) << "camera reflection";
      }
      if (xy.x() > 0.3 && xy.norm() < 0.8) {
        EXPECT_GT(conf, 0.99f);
        ++inside_right;
      }
    }
  EXPECT_GT(inside_right, 10);
}

TEST(SphereMapExtraction, MismatchedInputsAreRefused) {
  const LensModel lens = LensModel::pinhole(300, 64, 64);
  BallCone cone;
  cone.half_angle = 0.1;
  EXPECT_THROW(extract_sphere_map(cv::Mat(32, 64, CV_32FC3), {}, lens, cone, Mat3::Identity()), std::invalid_argument);
  EXPECT_THROW(extract_sphere_map(cv::Mat(64, 64, CV_32FC3), cv::Mat(64, 64, CV_32FC1), lens, cone, Mat3::Identity()),
               std::invalid_argument);
  cone.half_angle = 0;
  EXPECT_THROW(extract_sphere_map(cv::Mat(64, 64, CV_32FC3), {}, lens, cone, Mat3::Identity()), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
