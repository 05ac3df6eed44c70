// calib/orientation/ball_cube_features.h: the cube faces show the world direction each texel names (compared
// with the environment the view was rendered from), keypoints map back to pixels that reflect their
// directions exactly, and degenerate images give no features and no NaN.
#include "calib/orientation/ball_cube_features.h"

#include "calib_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace rsibr {
namespace {

using testing::kLobby;

struct View {
  testing::RenderedView r;
  BallCone cone;  // the true one
};

// One chrome ball of radius_px in the lobby, no noise.
View render(double radius_px) {
  const double distance = 0.5, f = radius_px * distance / 0.05;
  SynthScene scene =
      testing::rig_scene(LensModel::pinhole(f, int(2.5 * radius_px), int(2.3 * radius_px)), distance, false);
  scene.balls.resize(1);
  scene.environment.file = kLobby;
  scene.environment.sanitize = true;
  scene.views.front().azimuths_deg = {20};
  scene.views.front().roll_deg = 7;
  scene.views.front().look_at = scene.balls.front().centre;
  View v{testing::render_view(scene, 0), {}};
  const Vec3 c = testing::ball_centre_cam(v.r, 0);
  v.cone = {c.normalized(), std::asin(0.05 / c.norm())};
  return v;
}

double luminance(const Vec3& v) { return (v[0] + v[1] + v[2]) / 3; }

// Fraction of valid texels whose log ratio (face / environment at the world direction) is within
// 0.25 of the median (the chrome's Fresnel factor varies by < 0.15 in log over the used part).
double agreeing_fraction(const std::vector<CubeFace>& faces, const View& v, const Mat3& flip) {
  std::vector<double> lr;
  for (const CubeFace& face : faces)
    for (int y = 0; y < face.size; ++y)
      for (int x = 0; x < face.size; ++x) {
        if (!face.valid.at<unsigned char>(y, x)) continue;
        const cv::Vec3f p = face.radiance.at<cv::Vec3f>(y, x);
        float e[kMaxChannels];
        sample_bilinear(v.r.env, v.r.pose.world_from_cam * flip * face.direction(x, y), e);
        const double a = luminance(Vec3(p[0], p[1], p[2])), b = luminance(Vec3(e[0], e[1], e[2]));
        if (a > 0 && b > 0) lr.push_back(std::log(a / b));
      }
  if (lr.empty()) return 0;
  std::vector<double> s = lr;
  std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
  const double med = s[s.size() / 2];
  return double(std::count_if(lr.begin(), lr.end(), [&](double x) { return std::abs(x - med) < 0.25; })) / lr.size();
}

TEST(BallCubeFeatures, FaceTexelsShowTheWorldDirectionTheyName) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const View v = render(80);
  const std::vector<CubeFace> faces = ball_cube_faces(v.r.radiance, {}, v.r.scene.camera.lens, v.cone);
  ASSERT_EQ(faces.size(), 6u);
  // Face size from the radius: 2 tan(50 deg) / (2 / 80) = 95.3 -> 96 texels.
  EXPECT_EQ(faces[0].size, 96);
  int valid = 0;
  for (const CubeFace& f : faces) valid += cv::countNonZero(f.valid);
  EXPECT_GT(valid, 20000);  // most of the sphere minus the camera's cap and the cone behind the ball
  const double good = agreeing_fraction(faces, v, Mat3::Identity());
  // A wrong geometry (the directions mirrored left-right) fails the same measure: the test has teeth.
  const double wrong = agreeing_fraction(faces, v, Mat3(Vec3(-1, 1, 1).asDiagonal()));
  std::printf("  agreeing texels: %.3f (mirrored directions: %.3f)\n", good, wrong);
  EXPECT_GT(good, 0.9);
  EXPECT_LT(wrong, 0.6);
}

// CubeFace::texel inverts CubeFace::direction on every face, sub-texel, out to the face's corners
// (beyond [0, N-1] too: the gnomonic plane goes on); directions behind a face have no texel.
TEST(BallCubeFeatures, TexelOfDirectionRoundTripsOnEveryFace) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const View v = render(80);
  const std::vector<CubeFace> faces = ball_cube_faces(v.r.radiance, {}, v.r.scene.camera.lens, v.cone);
  for (const CubeFace& f : faces)
    for (double u : {-3.5, 0.0, 0.25, 47.5, 95.0, 99.75})
      for (double w : {-3.5, 0.0, 0.25, 47.5, 95.0, 99.75}) {
        const auto t = f.texel(f.direction(u, w));
        ASSERT_TRUE(t.has_value());
        EXPECT_NEAR(t->x(), u, 1e-9);
        EXPECT_NEAR(t->y(), w, 1e-9);
      }
  EXPECT_FALSE(faces[0].texel(-faces[0].axis).has_value());
  EXPECT_FALSE(faces[0].texel(faces[0].right).has_value());  // in the face's plane: at infinity
}

TEST(BallCubeFeatures, KeypointsMapBackToPixelsThatReflectTheirDirections) {
  if (!std::filesystem::exists(kLobby)) GTEST_SKIP() << kLobby << " missing (scripts/fetch-assets.sh)";
  const View v = render(80);
  const LensModel& lens = v.r.scene.camera.lens;
  BallFeatureOptions o{800, 0.3, 0.95, 25, 0.01};
  const BallFeatures f = ball_cube_features(v.r.radiance, {}, lens, v.cone, o);
  ASSERT_GT(f.directions.size(), 50u);
  ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.directions.size()));
  const Vec3 axis = v.cone.axis.normalized();
  double worst = 0, min_cam = 180;
  for (std::size_t i = 0; i < f.directions.size(); ++i) {
    const Vec3 r = reflect_off_ball<double>(f.rays[i], axis, std::sin(v.cone.half_angle)).normalized();
    worst = std::max(worst, angle_between(r, f.directions[i]));
    EXPECT_LT((lens.unproject(f.pixels[i]).normalized() - f.rays[i]).norm(), 1e-12);
    // Inside the used part of the ball, outside the camera's cap.
    EXPECT_LE(angle_between(f.rays[i], axis), 0.95 * v.cone.half_angle + 1e-9);
    min_cam = std::min(min_cam, angle_between(f.directions[i], -axis) * 180 / kPi);
    EXPECT_TRUE(std::isfinite(f.sigma[i]));
    // sigma = 0.3 px times the image's Jacobian, >= 0.3 x 2 / radius at the ball's centre.
    EXPECT_GE(f.sigma[i], 0.3 * 2 / 80 * 0.9);
  }
  EXPECT_LT(worst, 1e-7);  // the solve's recomputation from the ray agrees with the gnomonic direction
  EXPECT_GE(min_cam, 25 - 1e-9);
  // Each direction detected once: no two features closer than a tenth of a texel with near-equal
  // descriptors (the overlapping faces' duplicates are dropped).
  int duplicates = 0;
  for (std::size_t i = 0; i < f.directions.size(); ++i)
    for (std::size_t j = i + 1; j < f.directions.size(); ++j)
      if (angle_between(f.directions[i], f.directions[j]) < 0.1 * 2 / 80 &&
          cv::norm(f.descriptors.row(int(i)), f.descriptors.row(int(j))) < 1e-3)
        ++duplicates;
  EXPECT_EQ(duplicates, 0);
}

TEST(BallCubeFeatures, BlackClippedOrNonFiniteImagesGiveNoFeaturesAndNoNaN) {
  const LensModel lens = LensModel::pinhole(400, 100, 92);
  const BallCone cone{Vec3(0, 0, 1), std::asin(0.1)};
  cv::Mat black(92, 100, CV_32FC3, cv::Scalar::all(0));
  EXPECT_TRUE(ball_cube_features(black, {}, lens, cone).directions.empty());
  cv::Mat nan(92, 100, CV_32FC3, cv::Scalar::all(std::nan("")));
  EXPECT_TRUE(ball_cube_features(nan, {}, lens, cone).directions.empty());
  // A textured image whose every pixel is flagged clipped: no valid texel.
  cv::Mat tex(92, 100, CV_32FC3);
  cv::randu(tex, 0.0, 10.0);
  const cv::Mat clipped(92, 100, CV_8UC1, cv::Scalar(1));
  for (const CubeFace& face : ball_cube_faces(tex, clipped, lens, cone)) EXPECT_EQ(cv::countNonZero(face.valid), 0);
  EXPECT_TRUE(ball_cube_features(tex, clipped, lens, cone).directions.empty());
  // Unclipped, the same image gives finite features only.
  const BallFeatures f = ball_cube_features(tex, {}, lens, cone);
  for (std::size_t i = 0; i < f.directions.size(); ++i) {
    EXPECT_TRUE(f.directions[i].allFinite());
    EXPECT_TRUE(std::isfinite(f.sigma[i]) && f.sigma[i] > 0);
  }
  // Invalid inputs: one clear error.
  EXPECT_THROW(ball_cube_features(black, {}, lens, {Vec3(0, 0, 1), 0}), std::invalid_argument);
  EXPECT_THROW(ball_cube_features(cv::Mat(10, 10, CV_32FC3), {}, lens, cone), std::invalid_argument);
  EXPECT_THROW(ball_cube_features(black, cv::Mat(10, 10, CV_8UC1), lens, cone), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
