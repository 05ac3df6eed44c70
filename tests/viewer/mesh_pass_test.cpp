// The viewer's GPU paths against the CPU renderer (runtime/renderer.h), frame for frame.
// Runs under Xvfb with Mesa's software OpenGL (llvmpipe) in CI: tests/CMakeLists.txt runs this
// executable through `xvfb-run -a`.
//
// Tolerance and why: the shader evaluates the renderer's definitions in float32 where the CPU uses
// double (runtime/map_shader.h). Ray direction, warp and bilinear weights then differ by a few
// float ulps (~1e-7 relative), which moves a bilinear sample by ~1e-5 texel and changes the radiance
// by (map gradient) x 1e-5 texel: < 1e-4 relative for these smooth maps. Larger differences are
// allowed only where a decision is discontinuous and float and double may decide differently: a
// bilinear tap centred within rounding of the unit circle (kept or dropped), and silhouette pixels
// whose centre lies within rounding of a triangle edge (rasteriser and Embree's watertight test);
// both are rare (measured counts are printed). So: coverage differs on <= 0.5% of pixels, and of
// the pixels both cover, >= 99.5% agree within 1e-3 relative (per channel, relative to
// max(|cpu|, 0.05)) and every one within 0.02 relative (measured: 99.97%, max 1.6e-3 on the bunny).
#include "runtime/viewer/gl_frame.h"
#include "runtime/viewer/gl_map_set.h"
#include "runtime/viewer/gl_mesh.h"
#include "runtime/viewer/mesh_pass.h"

#include "bake/test_meshes.h"
#include "core/test_data.h"
#include "runtime/analytic_map_set.h"
#include "runtime/blend_engine.h"
#include "runtime/renderer.h"

#include "viewer/gl_test_context.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace rsibr {
namespace {

using viewer::GlFrame;
using viewer::GlMapSet;
using viewer::GlMesh;
using viewer::MeshPass;
using viewer::MeshPassOptions;

struct Agreement {
  long coverage_mismatch = 0, both = 0, within_tight = 0;
  double max_relative = 0;
  long non_finite = 0;
};

Agreement compare(const cv::Mat& gpu, const cv::Mat& cpu) {
  Agreement a;
  for (int r = 0; r < cpu.rows; ++r)
    for (int c = 0; c < cpu.cols; ++c) {
      const cv::Vec4f g = gpu.at<cv::Vec4f>(r, c), p = cpu.at<cv::Vec4f>(r, c);
      for (int k = 0; k < 4; ++k) a.non_finite += !std::isfinite(g[k]);
      if ((g[3] > 0.5f) != (p[3] > 0.5f)) {
        ++a.coverage_mismatch;
        continue;
      }
      if (p[3] < 0.5f) continue;
      ++a.both;
      double worst = 0;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(double(g[k]) - p[k]) / std::max(std::abs(double(p[k])), 0.05));
      a.within_tight += worst <= 1e-3;
      a.max_relative = std::max(a.max_relative, worst);
    }
  return a;
}

void expect_agreement(const Agreement& a, int pixels, const char* what) {
  std::printf("%s: %ld covered by both, %ld coverage mismatches, %.4f%% within 1e-3, max relative %.3g\n", what, a.both,
              a.coverage_mismatch, 100.0 * double(a.within_tight) / double(std::max(a.both, 1L)), a.max_relative);
  EXPECT_EQ(a.non_finite, 0) << what;
  EXPECT_GT(a.both, pixels / 20) << what << ": the mesh must cover a good part of the frame";
  EXPECT_LE(a.coverage_mismatch, pixels / 200) << what;
  EXPECT_GE(double(a.within_tight), 0.995 * double(a.both)) << what;
  EXPECT_LE(a.max_relative, 0.02) << what;
}

// An icosphere and a ground quad seen from below (back faces) and above.
Mesh scene_mesh() {
  Mesh m = test::icosphere(4, 1.0, Vec3(0, 0.2, 0));
  test::add_ground(m, 2.0, -0.9);
  return m;
}

cv::Mat gpu_frame(const Camera& cam, const Mesh& mesh, const MapSet& maps, const RenderOptions& ro,
                  const MeshPassOptions& mo) {
  testing::gl_test_context();
  const GlMesh gm(mesh);
  GlMapSet gs(maps, ro.blend, ro.warp, ro.map_size);
  const MeshPass pass;
  const GlFrame frame(cam.width, cam.height);
  frame.bind_and_clear();
  pass.draw(cam, mesh.bounds(), gm, gs, mo);
  return frame.read();
}

struct Case {
  const char* name;
  const char* warp;
  testing::TexelFunction f;
};

const Case kCases[] = {
    {"fresnel mirror", "mirror", testing::fresnel_mirror_texel},
    {"lambert normal", "normal", testing::lambert_texel},
};

TEST(MeshPass, PerPixelShaderMatchesTheCpuRenderer) {
  const Mesh mesh = scene_mesh();
  for (const Case& k : kCases) {
    const MapSet maps = testing::analytic_map_set(ViewSet::icosahedron(), 64, 64, k.warp, k.f);
    for (const Vec3& eye : {Vec3(0.3, 1.2, 4.0), Vec3(-2.5, -1.5, -2.0)}) {  // above and below the ground
      const Camera cam = look_at(eye, Vec3(0, 0, 0), Vec3(0, 1, 0), 50, 256, 192);
      RenderOptions ro;
      ro.mode = RenderMode::PerPixel;
      const cv::Mat cpu = Renderer(mesh, {&maps}, ro).render(cam);
      const cv::Mat gpu = gpu_frame(cam, mesh, maps, ro, {RenderMode::PerPixel, false});
      expect_agreement(compare(gpu, cpu), cam.width * cam.height, k.name);
    }
  }
}

TEST(MeshPass, PaperModeMatchesTheCpuRenderer) {
  const Mesh mesh = scene_mesh();
  for (const Case& k : kCases) {
    const MapSet maps = testing::analytic_map_set(ViewSet::icosahedron(), 64, 64, k.warp, k.f);
    const Camera cam = look_at(Vec3(0.3, 1.2, 4.0), Vec3(0, 0, 0), Vec3(0, 1, 0), 50, 256, 192);
    for (const char* warp : {"precomputed", "exact"}) {
      RenderOptions ro;
      ro.mode = RenderMode::Paper;
      ro.warp = warp;
      ro.map_size = 96;
      const cv::Mat cpu = Renderer(mesh, {&maps}, ro).render(cam);
      const cv::Mat gpu = gpu_frame(cam, mesh, maps, ro, {RenderMode::Paper, false});
      expect_agreement(compare(gpu, cpu), cam.width * cam.height, k.name);
    }
  }
}

// A captured set need not surround the sphere: views only around +Z (within 70 degrees). Seen from
// the side, many pixels' view directions fall outside every triangle, where locate projects them onto
// the covered region's boundary; the shader must do the same.
TEST(MeshPass, PerPixelShaderMatchesOutsideANonSurroundingSet) {
  std::vector<Vec3> views;
  const ViewSet all = ViewSet::geodesic(1);
  for (const Vec3& v : all.views())
    if (v.z() > std::cos(70.0 * 3.14159265358979 / 180.0)) views.push_back(v);
  const ViewSet partial(views);
  ASSERT_FALSE(partial.surrounds());
  const Mesh mesh = scene_mesh();
  const MapSet maps = testing::analytic_map_set(partial, 64, 64, "mirror", testing::fresnel_mirror_texel);
  const Camera cam = look_at(Vec3(3.5, 0.8, 1.0), Vec3(0, 0, 0), Vec3(0, 1, 0), 60, 256, 192);
  long outside = 0;
  for (int r = 0; r < cam.height; r += 4)
    for (int c = 0; c < cam.width; c += 4) outside += !partial.locate(-cam.ray_direction(c, r)).inside;
  EXPECT_GT(outside, 500) << "the camera must see view directions outside the set";
  RenderOptions ro;
  const cv::Mat cpu = Renderer(mesh, {&maps}, ro).render(cam);
  const cv::Mat gpu = gpu_frame(cam, mesh, maps, ro, {RenderMode::PerPixel, false});
  expect_agreement(compare(gpu, cpu), cam.width * cam.height, "non-surrounding");
}

// The per-pixel and paper modes differ where v_px departs from the central view (the paper
// mode's field-of-view error, runtime/renderer.h): the shader must show that difference, not
// hide it (a shader that ignored v_px would match paper mode instead).
TEST(MeshPass, PerPixelShaderUsesEachPixelsViewDirection) {
  const Mesh mesh = scene_mesh();
  const MapSet maps =
      testing::analytic_map_set(ViewSet::icosahedron(), 64, 64, "mirror", testing::fresnel_mirror_texel);
  const Camera cam = look_at(Vec3(0.3, 1.2, 3.0), Vec3(0, 0, 0), Vec3(0, 1, 0), 70, 256, 192);
  RenderOptions ro;
  ro.map_size = 64;
  const cv::Mat per_pixel = gpu_frame(cam, mesh, maps, ro, {RenderMode::PerPixel, false});
  const cv::Mat paper = gpu_frame(cam, mesh, maps, ro, {RenderMode::Paper, false});
  const Agreement a = compare(per_pixel, paper);
  EXPECT_LT(double(a.within_tight), 0.5 * double(a.both)) << "per-pixel and paper frames should differ";
}

// The weight view: sum_i a_i of the located sources, in [0, 1], exactly 1 where no source is faded
// (rim_fade 0 disables every fade), and the same as the CPU lookup's weight.
TEST(MeshPass, WeightViewIsTheSumOfFadedWeights) {
  const Mesh mesh = test::icosphere(4, 1.0);
  const MapSet maps = testing::analytic_map_set(ViewSet::icosahedron(), 64, 64, "mirror", testing::mirror_texel);
  const Camera cam = look_at(Vec3(0.4, 0.9, 3.5), Vec3(0, 0, 0), Vec3(0, 1, 0), 45, 128, 96);
  for (double fade : {0.0, 0.4}) {
    RenderOptions ro;
    ro.blend.rim_fade = fade;
    const cv::Mat w = gpu_frame(cam, mesh, maps, ro, {RenderMode::PerPixel, true});
    const ViewSet vs = maps.view_set();
    const BlendEngine lookup(maps, vs, ro.blend);
    long covered = 0, faded = 0;
    double worst = 0;
    for (int r = 0; r < w.rows; ++r)
      for (int c = 0; c < w.cols; ++c) {
        const cv::Vec4f g = w.at<cv::Vec4f>(r, c);
        if (g[3] < 0.5f) continue;
        ++covered;
        ASSERT_GE(g[0], 0.f);
        ASSERT_LE(g[0], 1.f + 1e-5f);
        faded += g[0] < 0.999f;
        // The CPU weight for the same pixel: the ray to the sphere and its normal.
        const Vec3 d = cam.ray_direction(c, r);
        const double b = cam.eye.dot(d), disc = b * b - (cam.eye.squaredNorm() - 1.0);
        if (disc < 1e-3) continue;  // grazing: the tessellated sphere differs from the exact one
        const Vec3 n = (cam.eye + (-b - std::sqrt(disc)) * d).normalized();
        double cpu_weight = 0;
        lookup.radiance(-d, n, &cpu_weight);
        worst = std::max(worst, std::abs(cpu_weight - g[0]));
      }
    EXPECT_GT(covered, 1000);
    if (fade == 0.0)
      EXPECT_EQ(faded, 0);
    else
      EXPECT_GT(faded, 0) << "some normals reflect near a source's singular direction";
    // The icosphere's interpolated normals differ from the exact sphere's by up to ~1e-2 rad at
    // level 4, so the weights agree loosely here (the exact comparison is the frame tests' job).
    EXPECT_LT(worst, 0.1) << "fade " << fade;
  }
}

// The bunny (the benchmark mesh) under a baked-like analytic set: the real mesh's many thin
// triangles and interpolated normals, per pixel.
TEST(MeshPass, BunnyPerPixelMatchesTheCpuRenderer) {
  const auto path = testing::assets_dir() / "models" / "bunny.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not fetched (scripts/fetch-assets.sh)";
  const Mesh mesh = load_mesh(path.string());
  const MapSet maps =
      testing::analytic_map_set(ViewSet::icosahedron(), 64, 64, "mirror", testing::fresnel_mirror_texel);
  const Camera cam = frame_bounds(mesh.bounds(), Vec3(0.3, -0.3, -1), Vec3(0, 1, 0), 40, 256, 192);
  RenderOptions ro;
  const cv::Mat cpu = Renderer(mesh, {&maps}, ro).render(cam);
  const cv::Mat gpu = gpu_frame(cam, mesh, maps, ro, {RenderMode::PerPixel, false});
  expect_agreement(compare(gpu, cpu), cam.width * cam.height, "bunny");
}

}  // namespace
}  // namespace rsibr
