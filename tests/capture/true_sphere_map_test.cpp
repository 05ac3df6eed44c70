// capture/true_sphere_map.h: the truth maps are what their contract says, in the view frame.
#include "capture/true_sphere_map.h"

#include "bake/brdf_spec.h"
#include "capture/camera_poses.h"
#include "capture/rig_renderer.h"
#include "capture/synth_capture.h"
#include "core/sphere_map.h"
#include "exact_irradiance.h"
#include "synth_cases.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

TEST(TrueSphereMap, GreyMapIsAlbedoTimesExactIrradianceOverPiInTheViewFrame) {
  // A 256-wide sky: the quadrature's rest level is 128 wide, so this measures that approximation too.
  SynthScene scene = testing::small_scene();
  scene.environment.size = 256;
  const EnvMap env = synth_environment(scene);
  const SynthBall& grey = scene.balls[1];
  const Vec3 eye(0.3, 1.6, 0.9);
  const int size = 16;
  const MapView mv = true_sphere_map(grey, eye, env, size);
  EXPECT_LT((mv.view - (eye - grey.centre).normalized()).norm(), 1e-12);
  EXPECT_EQ(mv.warp, CentralDirection::Normal);
  double worst = 0;
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
      const cv::Vec3f got = mv.rgb.at<cv::Vec3f>(r, c);
      if (xy.squaredNorm() >= 1) {
        EXPECT_EQ(got, cv::Vec3f(0, 0, 0));
        continue;
      }
      const Vec3 n = mv.world_from_view * sphere_map::g_normal(xy);
      const Vec3 want = grey.albedo.cwiseProduct(testing::exact_irradiance(env, n)) / kPi;
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(got[k] - want[k]) / want[k]);
    }
  EXPECT_LT(worst, 0.002) << worst;  // measured 0.08%
  std::cout << "grey truth map: worst relative error against the exact irradiance " << worst << "\n";
}

// The ray through the pixel where a ball's centre projects meets the ball where its normal is the
// view direction v (ball centre -> camera), so that pixel of the photo (before noise) must equal the
// truth map's centre texel (normal v), for every kind of ball: the photo and its truth agree.
TEST(TrueSphereMap, CentreTexelEqualsThePhotoAtTheBallCentre) {
  SynthScene scene = testing::small_scene();
  scene.stand = false;
  scene.photographer = false;
  scene.camera.lens = LensModel::pinhole(300, 95, 71);  // principal point (47, 35): a pixel centre
  SynthBall glossy;
  glossy.name = "glossy";
  glossy.kind = "glossy";
  glossy.centre = Vec3(0.3, 1.3, 0);
  glossy.brdf = "{type: ggx, roughness: 0.15, fresnel: {type: dielectric, ior: 1.5}}";
  scene.balls.push_back(glossy);
  scene.map_size = 17;  // the glossy ball's render reads its truth map
  const EnvMap env = synth_environment(scene);
  RigRenderOptions opt;
  opt.supersampling = 1;
  opt.jitter = false;
  const std::vector<SynthBall> balls = scene.balls;
  for (std::size_t b = 0; b < 3; ++b) {
    scene.balls = {balls[b]};  // alone: no ball occludes another
    const RigRenderer renderer(scene, env);
    SynthViewPlan plan;
    plan.plan = "ring";
    plan.count = 1;
    plan.azimuth0_deg = 30;
    plan.distance_m = 0.7;
    plan.look_at = balls[b].centre;
    scene.views = {plan};
    const CameraPose pose = plan_camera_poses(scene).front();
    const cv::Mat img = renderer.render(pose, scene.camera.lens, RayTable(scene.camera.lens), opt);
    const MapView mv = true_sphere_map(balls[b], pose.eye, env, 17);
    const cv::Vec3f photo = img.at<cv::Vec3f>(35, 47), truth = mv.rgb.at<cv::Vec3f>(8, 8);
    // chrome: the same lookup; grey: the irradiance map; glossy: the map itself at its centre texel.
    const double tol = b == 1 ? 2e-3 : 1e-5;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(photo[k], truth[k], tol * truth[k]) << balls[b].name << " " << k;
  }
}

TEST(TrueSphereMap, ChromeMapIsFresnelTimesTheEnvironmentSeenInTheMirror) {
  // Under a constant environment L, every texel inside the disc is F(cos) L with cos = n.v, and the
  // centre texels (n ~ v) reflect at normal incidence.
  SynthScene scene = testing::small_scene();
  EnvMap env = EnvMap::zeros(Layout::with_size(LayoutKind::LatLong, 32), 3);
  env.pixels.setTo(cv::Scalar(2, 2, 2));
  const SynthBall& chrome = scene.balls[0];
  const MapView mv = true_sphere_map(chrome, Vec3(0, 1.3, 2), env, 32);
  const auto f = make_fresnel(YAML::Load(chrome.fresnel));
  EXPECT_EQ(mv.warp, CentralDirection::Mirror);
  for (int r = 0; r < 32; ++r)
    for (int c = 0; c < 32; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), 32, 32);
      if (xy.squaredNorm() >= 1) continue;
      const double cosine = sphere_map::g_normal(xy).z();
      EXPECT_NEAR(mv.rgb.at<cv::Vec3f>(r, c)[0], 2 * f->eval(cosine)[0], 1e-5);
    }
}

}  // namespace
}  // namespace rsibr
