// calib/probe/probe.h: chrome views extracted by calib/ from rendered photos (photographer in the shot),
// blended into a lat-long probe and measured against the true environment.
#include "calib/probe/probe.h"

#include "bake/brdf_spec.h"
#include "calib/balls/ball_locator.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "calib_cases.h"
#include "core/sphere_map.h"

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

// Five views of a sun clipped in every bracket, a texel or two wide in each view's map, each view's
// frame off by 1.2 degrees about a different axis (as solved orientations are); the views' map sizes
// `sizes` (default 128).
MapSet clipped_sun_views(const Vec3& sun, const std::vector<int>& sizes = std::vector<int>(5, 128)) {
  const Vec3 axes[5] = {{1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}, {0.7, 0, 0.7}};
  MapSet set;
  for (int v = 0; v < 5; ++v) {
    MapView mv;
    const int size = sizes[std::size_t(v)];
    mv.source = MapSource::Captured;
    // The view's frame as registered: the true frame turned by 1.2 degrees about a horizontal axis.
    const Mat3 err = Eigen::AngleAxisd(1.2 * kPi / 180, axes[v].normalized()).toRotationMatrix();
    mv.world_from_view = Mat3::Identity();
    mv.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar::all(1.0));
    mv.confidence = cv::Mat(size, size, CV_32FC1, cv::Scalar(1.0));
    mv.clipped = cv::Mat(size, size, CV_32FC1, cv::Scalar(0.0));
    // Where this view saw the sun (its frame's error moves it); the texels within 1 degree clipped,
    // at least the nearest.
    const Vec3 seen = err * sun;
    const Vec2 p = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(seen), size, size);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const Vec2 d = sphere_map::disc_from_pixel(Vec2(x, y), size, size);
        if (d.squaredNorm() >= 1) {
          mv.confidence.at<float>(y, x) = 0;
          continue;
        }
        const bool nearest = std::lround(p.x()) == x && std::lround(p.y()) == y;
        if (nearest || angle_between(sphere_map::g_mirror(d), seen) < kPi / 180) {
          mv.confidence.at<float>(y, x) = 0;
          mv.clipped.at<float>(y, x) = 1;
          mv.rgb.at<cv::Vec3f>(y, x) = cv::Vec3f(50, 50, 50);
        }
      }
    set.views.push_back(mv);
  }
  return set;
}

// A sun clipped in every view, a texel or two wide in each view's map, where each view's frame is
// off by a degree or so (as solved orientations are): every view's clipped spot lies a little apart
// from the others', so at each probe texel one view says "clipped" and the rest see sky there. The
// sun must stay a lower bound in the probe: views that clipped it within the registration error do
// not vote it away (without that rule no texel of the probe is clipped).
TEST(Probe, ASunClippedInEveryViewSurvivesTheViewsRegistrationSpread) {
  const int size = 128;
  const Vec3 sun = Vec3(0.3, 0.8, 0.5).normalized();
  const MapSet set = clipped_sun_views(sun);
  ProbeOptions po;
  po.width = 512;
  const Probe p = assemble_probe(set, po);
  // Solid angles: a lat-long texel (2 pi / W)(pi / H) cos(latitude); an equal-area sphere-map texel
  // 16 / size^2 (the unit disc holds 4 pi sr).
  auto lower_bound_sr = [](const Probe& q) {
    double sr = 0;
    for (int r = 0; r < q.clipped.rows; ++r)
      for (int c = 0; c < q.clipped.cols; ++c)
        if (q.clipped.at<float>(r, c) > 0)
          sr += 2 * kPi / q.clipped.cols * kPi / q.clipped.rows *
                std::sqrt(std::max(0.0, 1 - std::pow(q.env.layout.texel_direction(c, r)->y(), 2)));
    return sr;
  };
  const double one_view_sr = cv::countNonZero(set.views[0].clipped > 0) * 16.0 / (size * size);
  double nearest = 1e9;
  for (int r = 0; r < p.clipped.rows; ++r)
    for (int c = 0; c < p.clipped.cols; ++c)
      if (p.clipped.at<float>(r, c) > 0) {
        nearest = std::min(nearest, angle_between(*p.env.layout.texel_direction(c, r), sun));
        EXPECT_GE(p.lower_bound.at<cv::Vec3f>(r, c)[0], 49.f);
      }
  EXPECT_GE(lower_bound_sr(p), one_view_sr) << "the sun was voted away";
  EXPECT_LT(nearest * 180 / kPi, 1.0);
  // The case this rule exists for: without it (every trusted lookup votes) the probe keeps only
  // where the views' spots overlap, less than any one view saw.
  ProbeOptions strict = po;
  strict.registration_deg = 0;
  EXPECT_LT(lower_bound_sr(assemble_probe(set, strict)), one_view_sr);
  // The sky away from the sun is the views' trusted blend, never a lower bound.
  for (int r = 0; r < p.clipped.rows; ++r)
    for (int c = 0; c < p.clipped.cols; ++c)
      if (angle_between(*p.env.layout.texel_direction(c, r), sun) > 6 * kPi / 180)
        ASSERT_EQ(p.clipped.at<float>(r, c), 0.f) << "row " << r << " col " << c;
}

// The jackknife's folds made in one pass are the probes of the views without each one, to the bit:
// views of one size, one view coarser, and one view finer than the rest on a probe coarser than the
// maps (without it the others' probe subsamples each texel less: that fold is made on its own).
TEST(Probe, FoldsInOnePassAreTheProbesWithoutEachView) {
  const Vec3 sun = Vec3(0.3, 0.8, 0.5).normalized();
  const auto fresnel = make_fresnel(YAML::Load(kDefaultChromeFresnel));
  const std::vector<std::vector<int>> cases = {
      {128, 128, 128, 128, 128}, {128, 128, 64, 128, 128}, {128, 64, 64, 64, 64}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    MapSet set = clipped_sun_views(sun, cases[i]);
    // Each view's own sky, so that leaving any one out changes the probe.
    for (std::size_t v = 0; v < set.views.size(); ++v)
      set.views[v].rgb.setTo(cv::Scalar::all(1.0 + 0.1 * double(v)), set.views[v].clipped == 0);
    ProbeOptions po;
    po.width = i == 2 ? 64 : 256;
    po.fresnel = fresnel.get();
    const std::vector<EnvMap> folds = assemble_probe_folds(set, po);
    const EnvMap whole = assemble_probe(set, po).env;
    ASSERT_EQ(folds.size(), set.views.size());
    for (std::size_t v = 0; v < set.views.size(); ++v) {
      MapSet rest;
      for (std::size_t u = 0; u < set.views.size(); ++u)
        if (u != v) rest.views.push_back(set.views[u]);
      const EnvMap alone = assemble_probe(rest, po).env;
      EXPECT_EQ(cv::norm(folds[v].pixels, alone.pixels, cv::NORM_INF), 0.0) << "case " << i << ", view " << v;
      EXPECT_GT(cv::norm(folds[v].pixels, whole.pixels, cv::NORM_INF), 0.0);
    }
  }
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
