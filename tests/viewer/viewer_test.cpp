// The viewer's scripted mode (runtime/viewer/viewer.h): turntable frames as rsibr render's, and
// the comparison of two map sets (wipe, side by side) showing each set on its own side.
// Runs under Xvfb (tests/CMakeLists.txt).
#include "runtime/viewer/viewer.h"

#include "bake/test_meshes.h"
#include "runtime/analytic_map_set.h"
#include "runtime/renderer.h"
#include "viewer/gl_test_context.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

using viewer::Compare;
using viewer::ScriptedFrame;
using viewer::ViewerScene;
using viewer::ViewerSettings;

std::vector<cv::Mat> scripted(const ViewerScene& scene, const ViewerSettings& st, int frames,
                              std::vector<Camera>* cameras = nullptr) {
  std::vector<cv::Mat> out;
  viewer::run_scripted(scene, st, frames, true, [&](const ScriptedFrame& f) {
    EXPECT_TRUE(std::isfinite(f.seconds) && f.seconds > 0);
    out.push_back(f.rgba);
    if (cameras) cameras->push_back(f.camera);
  });
  return out;
}

// Largest colour difference, relative to max(|b|, 0.05), over columns [c0, c1) where both cover.
double worst_relative(const cv::Mat& a, const cv::Mat& b, int c0, int c1, long* both = nullptr) {
  double worst = 0;
  long n = 0;
  for (int r = 0; r < a.rows; ++r)
    for (int c = c0; c < c1; ++c) {
      const cv::Vec4f x = a.at<cv::Vec4f>(r, c), y = b.at<cv::Vec4f>(r, c);
      if (x[3] < 0.5f || y[3] < 0.5f) continue;
      ++n;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(double(x[k]) - y[k]) / std::max(std::abs(double(y[k])), 0.05));
    }
  if (both) *both = n;
  return worst;
}

struct Fixture {
  Mesh mesh = test::icosphere(4, 1.0);
  MapSet mirror = testing::analytic_map_set(ViewSet::icosahedron(), 48, 48, "mirror", testing::mirror_texel);
  MapSet lambert = testing::analytic_map_set(ViewSet::icosahedron(), 48, 48, "normal", testing::lambert_texel);
  ViewerSettings settings() const {
    ViewerSettings st;
    st.camera = look_at(Vec3(0.5, 1.0, 3.5), Vec3(0, 0, 0), Vec3(0, 1, 0), 40, 128, 96);
    st.pivot = Vec3(0, 0, 0);
    st.up = Vec3(0, 1, 0);
    return st;
  }
};

// Frame k of --orbit N is the camera of rsibr render --turntable N, and matches the CPU renderer.
TEST(Viewer, ScriptedOrbitMatchesTheRenderersTurntable) {
  const Fixture f;
  ViewerScene scene{&f.mesh, {&f.mirror}, {"mirror"}};
  std::vector<Camera> cams;
  const auto frames = scripted(scene, f.settings(), 3, &cams);
  ASSERT_EQ(frames.size(), 3u);
  const Renderer cpu(f.mesh, {&f.mirror});
  for (int k = 0; k < 3; ++k) {
    const Camera expected = orbit(f.settings().camera, Vec3(0, 0, 0), Vec3(0, 1, 0), k, 3);
    EXPECT_LT((cams[std::size_t(k)].eye - expected.eye).norm(), 1e-12);
    long both = 0;
    EXPECT_LT(worst_relative(frames[std::size_t(k)], cpu.render(expected), 0, 128, &both), 0.02) << "frame " << k;
    EXPECT_GT(both, 1000);
  }
}

// Wipe at 0.5: columns left of 64 show the first set, the rest the second; side by side: each half
// is that set seen by a camera of half the width (the CPU renderer with the same half camera).
TEST(Viewer, ComparisonShowsEachSetOnItsSide) {
  const Fixture f;
  ViewerScene scene{&f.mesh, {&f.mirror, &f.lambert}, {"mirror", "lambert"}};
  ViewerSettings st = f.settings();
  st.compare = Compare::Wipe;
  st.wipe = 0.5f;
  const cv::Mat wipe = scripted(scene, st, 1).front();
  const cv::Mat a = Renderer(f.mesh, {&f.mirror}).render(st.camera);
  const cv::Mat b = Renderer(f.mesh, {&f.lambert}).render(st.camera);
  EXPECT_LT(worst_relative(wipe, a, 0, 64), 0.02);
  EXPECT_LT(worst_relative(wipe, b, 64, 128), 0.02);
  EXPECT_GT(worst_relative(wipe, b, 0, 64), 0.1) << "the left half must not show the second set";

  st.compare = Compare::SideBySide;
  const cv::Mat side = scripted(scene, st, 1).front();
  Camera half = st.camera;
  half.width = 64;
  half.cx = st.camera.cx - 32;
  const cv::Mat ha = Renderer(f.mesh, {&f.mirror}).render(half);
  const cv::Mat hb = Renderer(f.mesh, {&f.lambert}).render(half);
  long n = 0;
  EXPECT_LT(worst_relative(side.colRange(0, 64), ha, 0, 64, &n), 0.02);
  EXPECT_GT(n, 500);
  EXPECT_LT(worst_relative(side.colRange(64, 128), hb, 0, 64, &n), 0.02);
  EXPECT_GT(n, 500);
}

}  // namespace
}  // namespace rsibr
