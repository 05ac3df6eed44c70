// calib/probe/probe.h: chrome views extracted by calib/ from rendered photos (photographer in the shot),
// blended into a lat-long probe and measured against the true environment.
#include "calib/probe/probe.h"

#include "bake/brdf_spec.h"
#include "calib/balls/ball_locator.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "calib_cases.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

struct ProbeError {
  double relative_rms = 0, covered = 0;
};

// Solid-angle weighted relative RMS over the texels the probe covers.
ProbeError probe_error(const Probe& p, const EnvMap& truth) {
  double num = 0, den = 0;
  for (int r = 0; r < p.env.pixels.rows; ++r)
    for (int c = 0; c < p.env.pixels.cols; ++c) {
      if (!(p.weight.at<float>(r, c) > 0)) continue;
      const Vec3 w = *p.env.layout.texel_direction(c, r);
      const double a = std::sqrt(std::max(0.0, 1 - w.y() * w.y()));
      float t[3];
      sample_bilinear(truth, w, t);
      const cv::Vec3f v = p.env.pixels.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) num += a * (v[k] - t[k]) * (v[k] - t[k]), den += a * t[k] * t[k];
    }
  return {std::sqrt(num / den), p.covered_fraction};
}

// Four views on a ring with the photographer behind each camera: every view's camera and
// photographer (masked 50 degrees around the camera in its own map) are seen past by the others, so
// the probe covers the whole sphere and matches the sky to 1% once the ball's Fresnel is divided out
// (0.4% measured; the photographer unmasked at 20 degrees gives 7%).
TEST(Probe, FourChromeViewsGiveTheEnvironmentWithoutTheCamera) {
  const double distance = 0.6, f = 60 * distance / 0.05;
  SynthScene scene = testing::rig_scene(LensModel::pinhole(f, 192, 156), distance, false);
  scene.balls.resize(1);
  scene.photographer = true;
  scene.environment.sun_rgb = Vec3::Zero();  // the geometry's error, not the sun disc's sampling
  scene.views.front().count = 4;
  scene.views.front().look_at = scene.balls.front().centre;
  const auto fresnel = make_fresnel(YAML::Load(scene.balls.front().fresnel));
  MapSet set;
  EnvMap env;
  for (int v = 0; v < 4; ++v) {
    const auto view = testing::render_view(scene, v);
    env = view.env;
    const LensModel& lens = scene.camera.lens;
    const BallLocation loc = locate_ball(view.radiance, lens, {testing::ball_centre_px(view, 0) + Vec2(1, -1), 62});
    ExtractOptions opt;
    opt.size = 64;
    opt.camera_mask_deg = 50;  // the photographer proxy, a body behind a camera 0.6 m away, spans ~45 degrees
    set.views.push_back(extract_sphere_map(view.radiance, {}, lens, loc.fit.cone, view.pose.world_from_cam, opt));
  }
  ProbeOptions po;
  po.width = 128;
  po.fresnel = fresnel.get();
  const Probe all = assemble_probe(set, po);
  const ProbeError e = probe_error(all, env);
  MapSet one;
  one.views.push_back(set.views.front());
  const Probe single = assemble_probe(one, po);
  std::printf("  probe of 4 views: relative RMS %.4f, covered %.3f; one view: covered %.3f\n", e.relative_rms,
              e.covered, single.covered_fraction);
  EXPECT_LT(e.relative_rms, 0.01);
  EXPECT_GT(e.covered, 0.95);
  EXPECT_GT(e.covered, single.covered_fraction + 0.03);  // the others fill view 0's camera
  for (auto it = all.env.pixels.begin<cv::Vec3f>(); it != all.env.pixels.end<cv::Vec3f>(); ++it)
    ASSERT_TRUE(std::isfinite((*it)[0]) && std::isfinite((*it)[1]) && std::isfinite((*it)[2]));
}

TEST(Probe, ComputedMapsOrNoViewsAreRefused) {
  EXPECT_THROW(assemble_probe(MapSet{}), std::invalid_argument);
  MapSet s;
  s.views.push_back(MapView{});
  s.views.back().rgb = cv::Mat(8, 8, CV_32FC3, cv::Scalar::all(1));
  EXPECT_THROW(assemble_probe(s), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
