// capture/rig_renderer.h: analytic checks of the renderer before noise.
#include "capture/rig_renderer.h"

#include "bake/brdf_spec.h"
#include "capture/synth_capture.h"
#include "exact_irradiance.h"
#include "synth_cases.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// Independent sphere intersection (the textbook quadratic in long double).
bool hit_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double r, Vec3* p) {
  const long double b = (o - c).dot(d), cc = (o - c).squaredNorm() - r * r;
  const long double disc = b * b - cc;
  if (disc < 0) return false;
  const long double t = -b - std::sqrt(disc);
  *p = o + double(t) * d;
  return t > 0;
}

struct Fixture {
  SynthScene scene;
  EnvMap env;
  CameraPose pose;
  Fixture(const std::string& balls_filter) {
    scene = testing::small_scene();
    scene.environment.size = 256;  // wider than the quadrature's 128-wide rest level
    scene.stand = false;
    scene.photographer = false;
    std::vector<SynthBall> keep;
    for (const SynthBall& b : scene.balls)
      if (b.kind == balls_filter) keep.push_back(b);
    scene.balls = keep;
    env = synth_environment(scene);
    pose = plan_camera_poses(scene).front();
  }
};

TEST(RigRenderer, ChromePixelEqualsFresnelTimesEnvironmentAlongTheExactReflectedRay) {
  Fixture f("chrome");
  const SynthBall& ball = f.scene.balls.front();
  const RigRenderer renderer(f.scene, f.env);
  const LensModel& lens = f.scene.camera.lens;
  RigRenderOptions opt;
  opt.supersampling = 1;
  opt.jitter = false;
  const cv::Mat img = renderer.render(f.pose, lens, RayTable(lens), opt);
  const auto fresnel = make_fresnel(YAML::Load(ball.fresnel));
  int on_ball = 0;
  double worst = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const Vec3 d = f.pose.world_from_cam * lens.unproject(Vec2(x, y));
      Vec3 p;
      if (!hit_sphere(f.pose.eye, d, ball.centre, 0.5 * ball.diameter_m, &p)) continue;
      const Vec3 n = (p - ball.centre).normalized();
      const double cosine = -d.dot(n);
      const Vec3 r = d + 2 * cosine * n;
      float L[4];
      sample_bilinear(f.env, r, L);
      const Vec3 F = fresnel->eval(cosine);
      const cv::Vec3f got = img.at<cv::Vec3f>(y, x);
      for (int k = 0; k < 3; ++k) {
        const double want = F[k] * L[k];
        worst = std::max(worst, std::abs(got[k] - want) / std::max(want, 1e-3));
      }
      ++on_ball;
    }
  EXPECT_GT(on_ball, 200);
  EXPECT_LT(worst, 1e-5);  // float precision: the same ray, the same lookup
}

TEST(RigRenderer, ChromeReflectsAboutSixtyPercentAtNormalIncidence) {
  Fixture f("chrome");
  const auto fresnel = make_fresnel(YAML::Load(f.scene.balls.front().fresnel));
  const Vec3 f0 = fresnel->eval(1.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(f0[k], 0.5);
    EXPECT_LT(f0[k], 0.65);
  }
}

TEST(RigRenderer, GreyPixelEqualsAlbedoTimesIrradianceOverPi) {
  Fixture f("grey");
  const SynthBall& ball = f.scene.balls.front();
  const RigRenderer renderer(f.scene, f.env);
  const LensModel& lens = f.scene.camera.lens;
  RigRenderOptions opt;
  opt.supersampling = 1;
  opt.jitter = false;
  const cv::Mat img = renderer.render(f.pose, lens, RayTable(lens), opt);
  double worst = 0;
  int checked = 0;
  for (int y = 0; y < img.rows; y += 2)
    for (int x = 0; x < img.cols; x += 2) {
      const Vec3 d = f.pose.world_from_cam * lens.unproject(Vec2(x, y));
      Vec3 p;
      if (!hit_sphere(f.pose.eye, d, ball.centre, 0.5 * ball.diameter_m, &p)) continue;
      const Vec3 n = (p - ball.centre).normalized();
      const Vec3 want = ball.albedo.cwiseProduct(testing::exact_irradiance(f.env, n)) / kPi;
      const cv::Vec3f got = img.at<cv::Vec3f>(y, x);
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(got[k] - want[k]) / want[k]);
      ++checked;
    }
  EXPECT_GT(checked, 40);
  // The irradiance map's accuracy (256 x 128, bilinear; measured 0.076%).
  EXPECT_LT(worst, 0.002) << "worst relative error " << worst;
  std::cout << "grey ball: worst relative error against the exact irradiance " << worst << " over " << checked
            << " pixels\n";
}

TEST(RigRenderer, PhotographerAppearsInTheChromeBallAndNeverBlocksTheView) {
  Fixture f("chrome");
  f.scene.photographer = true;
  const RigRenderer renderer(f.scene, f.env);
  const LensModel& lens = f.scene.camera.lens;
  RigRenderOptions opt;
  opt.supersampling = 1;
  opt.jitter = false;
  const cv::Mat with = renderer.render(f.pose, lens, RayTable(lens), opt);
  f.scene.photographer = false;
  const cv::Mat without = RigRenderer(f.scene, f.env).render(f.pose, lens, RayTable(lens), opt);
  // The ball's centre pixel reflects the ray back toward the camera: the camera body (dark) there.
  const Vec3 c_cam = f.pose.world_from_cam.transpose() * (f.scene.balls.front().centre - f.pose.eye);
  const Vec2 c = lens.project(c_cam);
  const int cx = int(std::lround(c.x())), cy = int(std::lround(c.y()));
  EXPECT_LT(with.at<cv::Vec3f>(cy, cx)[1], 0.5 * without.at<cv::Vec3f>(cy, cx)[1]);
  // Off the ball nothing changes: the proxy is behind the camera.
  int changed_off_ball = 0;
  for (int y = 0; y < with.rows; ++y)
    for (int x = 0; x < with.cols; ++x) {
      const Vec3 d = f.pose.world_from_cam * lens.unproject(Vec2(x, y));
      Vec3 p;
      if (hit_sphere(f.pose.eye, d, f.scene.balls.front().centre, 0.5 * f.scene.balls.front().diameter_m, &p)) continue;
      changed_off_ball += with.at<cv::Vec3f>(y, x) != without.at<cv::Vec3f>(y, x);
    }
  EXPECT_EQ(changed_off_ball, 0);
}

// Centre pixel of the first ball of the fixture, rendered with or without the photographer.
cv::Vec3f centre_pixel(Fixture& f, bool photographer) {
  f.scene.photographer = photographer;
  const RigRenderer renderer(f.scene, f.env);
  const LensModel& lens = f.scene.camera.lens;
  RigRenderOptions opt;
  opt.supersampling = 1;
  opt.jitter = false;
  const cv::Mat img = renderer.render(f.pose, lens, RayTable(lens), opt);
  const Vec2 c = lens.project(f.pose.world_from_cam.transpose() * (f.scene.balls.front().centre - f.pose.eye));
  return img.at<cv::Vec3f>(int(std::lround(c.y())), int(std::lround(c.x())));
}

TEST(RigRenderer, PhotographerShadowsTheGreyBallWhenTheSunIsBehindHim) {
  Fixture f("grey");
  // The sun straight behind the photographer's torso as seen from the ball (torso box centre in
  // the camera frame: (0, 0.46, -0.29)).
  const Vec3 torso = f.pose.eye + f.pose.world_from_cam * Vec3(0, 0.46, -0.29);
  f.scene.environment.sun_direction = (torso - f.scene.balls.front().centre).normalized();
  f.scene.environment.sun_rgb = Vec3::Constant(5000);
  f.env = synth_environment(f.scene);
  const cv::Vec3f lit = centre_pixel(f, false), shadowed = centre_pixel(f, true);
  EXPECT_LT(shadowed[1], 0.5f * lit[1]) << lit[1] << " " << shadowed[1];
  EXPECT_GT(shadowed[1], 0.0f);
}

TEST(RigRenderer, PhotographerDarkensTheGreyBallSlightlyUnderAnOvercastSky) {
  Fixture f("grey");
  f.env = EnvMap::zeros(Layout::with_size(LayoutKind::LatLong, 64), 3);
  f.env.pixels.setTo(cv::Scalar(1, 1, 1));
  const cv::Vec3f open = centre_pixel(f, false), blocked = centre_pixel(f, true);
  // Unoccluded, a constant sky gives exactly albedo * L (E = pi L).
  EXPECT_NEAR(open[1], 0.18f, 0.18f * 1e-3f);
  // The proxy (about 0.1 sr right behind the camera at 0.8 m, albedo 0.25 and 0.04) takes a few
  // percent of the light where the ball faces the camera.
  EXPECT_LT(blocked[1], open[1] * 0.99f);
  EXPECT_GT(blocked[1], open[1] * 0.85f);
  std::cout << "photographer: grey ball centre " << blocked[1] / open[1] << " of its unoccluded value\n";
}

TEST(RigRenderer, SupersampledEdgeIsAntialiased) {
  Fixture f("grey");
  const RigRenderer renderer(f.scene, f.env);
  const LensModel& lens = f.scene.camera.lens;
  RigRenderOptions opt;
  opt.supersampling = 4;
  const cv::Mat img = renderer.render(f.pose, lens, RayTable(lens), opt);
  opt.supersampling = 1;
  opt.jitter = false;
  const cv::Mat point = renderer.render(f.pose, lens, RayTable(lens), opt);
  // Pixels that straddle the ball's outline take values strictly between ball and background.
  int mixed = 0;
  for (int y = 1; y + 1 < img.rows; ++y)
    for (int x = 1; x + 1 < img.cols; ++x) {
      const float a = img.at<cv::Vec3f>(y, x)[1], p = point.at<cv::Vec3f>(y, x)[1];
      const float l = point.at<cv::Vec3f>(y, x - 1)[1], r = point.at<cv::Vec3f>(y, x + 1)[1];
      if (std::abs(l - r) > 0.2f * std::max(l, r) && std::abs(a - p) > 1e-4f && a > std::min(l, r) &&
          a < std::max(l, r))
        ++mixed;
    }
  EXPECT_GT(mixed, 10);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(img.at<cv::Vec3f>(y, x)[k]));
}

}  // namespace
}  // namespace rsibr
