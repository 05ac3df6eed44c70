#include "runtime/renderer.h"

#include "analytic_map_set.h"
#include "runtime/blend_engine.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>

namespace rsibr {
namespace {

using namespace rsibr::testing;

// A UV sphere of radius `radius` at `centre` with exact (radial) vertex normals, counter-clockwise
// seen from outside.
Mesh test_sphere(int rings = 48, int segments = 96, double radius = 1.0, const Vec3& centre = Vec3::Zero()) {
  Mesh m;
  auto add = [&](const Vec3& n) {
    m.positions.push_back((centre + radius * n).cast<float>());
    m.normals.push_back(n.cast<float>());
    return uint32_t(m.positions.size() - 1);
  };
  const uint32_t north = add(Vec3(0, 1, 0));
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = kPi * i / rings, ph = 2 * kPi * j / segments;
      add(Vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  const uint32_t south = add(Vec3(0, -1, 0));
  auto at = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
    const Vec3 pa = m.positions[a].cast<double>(), pb = m.positions[b].cast<double>(),
               pc = m.positions[c].cast<double>();
    if ((pb - pa).cross(pc - pa).dot(pa + pb + pc - 3 * centre) < 0) std::swap(b, c);
    m.triangles.push_back({a, b, c});
  };
  for (int j = 0; j < segments; ++j) {
    tri(north, at(1, j), at(1, j + 1));
    tri(south, at(rings - 1, j), at(rings - 1, j + 1));
    for (int i = 1; i + 1 < rings; ++i) {
      tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return m;
}

// A square of side `side` centred at the origin, perpendicular to `normal`, every vertex normal `normal`.
Mesh quad_mesh(const Vec3& normal, double side) {
  const Mat3 T = world_from_view_for(normal);
  Mesh m;
  for (const auto& [x, y] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
    m.positions.push_back((0.5 * side * (x * T.col(0) + y * T.col(1))).cast<float>());
    m.normals.push_back(normal.normalized().cast<float>());
  }
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

Vec3 reflect(const Vec3& v, const Vec3& n) { return 2 * n.dot(v) * n - v; }

struct PixelHit {
  bool hit = false;
  Vec3 n, v;  // shading normal (toward the eye), direction to the eye
};

// The renderer's own visibility for pixel (c, r): the test's independent route to n and v.
PixelHit trace(const Renderer& renderer, const Camera& cam, int c, int r) {
  const Vec3 d = cam.ray_direction(c, r);
  const RayHit h = renderer.scene().intersect(cam.eye, d);
  PixelHit p;
  if (!h.hit) return p;
  p.hit = true;
  p.n = renderer.scene().shading_normal(h);
  if (renderer.scene().geometric_normal(h).dot(d) > 0) p.n = -p.n;
  p.v = -d;
  return p;
}

Vec3 pixel(const cv::Mat& img, int c, int r) {
  const cv::Vec4f o = img.at<cv::Vec4f>(r, c);
  return Vec3(o[0], o[1], o[2]);
}

RenderOptions with_mode(RenderMode mode, int map_size = 0) {
  RenderOptions o;
  o.mode = mode;
  o.map_size = map_size;
  return o;
}

// A 42-view set of 128^2 maps of f times a texel-scale checker (0.2 and 1.0 alternating per texel):
// detail that one tap per pixel aliases on a small object.
MapSet checker_set(const std::string& warp, const TexelFunction& f) {
  MapSet set = analytic_map_set(ViewSet::named("42"), 128, 128, warp, f);
  for (MapView& v : set.views)
    for (int r = 0; r < 128; ++r)
      for (int c = 0; c < 128; ++c) v.rgb.at<cv::Vec3f>(r, c) *= ((r + c) % 2) ? 1.0f : 0.2f;
  return set;
}

// RMS of a - ref (RGB) over the pixels both cover fully (alpha 1); *count gets how many.
double interior_rms(const cv::Mat& a, const cv::Mat& ref, int* count) {
  double e = 0;
  int n = 0;
  for (int r = 0; r < ref.rows; ++r)
    for (int c = 0; c < ref.cols; ++c) {
      if (ref.at<cv::Vec4f>(r, c)[3] < 1.0f || a.at<cv::Vec4f>(r, c)[3] < 1.0f) continue;
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(std::isfinite(a.at<cv::Vec4f>(r, c)[k]));
        e += std::pow(a.at<cv::Vec4f>(r, c)[k] - ref.at<cv::Vec4f>(r, c)[k], 2);
      }
      ++n;
    }
  *count = n;
  return std::sqrt(e / std::max(1, 3 * n));
}

// A small object (an ~18 px sphere) rendered with one tap per source and with lookups at each pixel's
// level of detail, each against a 64-sample supersampled render in the same mode: RMS of both.
struct LodErrors {
  double point = 0, lod = 0;
};
LodErrors small_sphere_lod_errors(const MapSet& set, const Mesh& mesh, RenderOptions o) {
  const Camera cam = look_at(Vec3(2.0, 3.0, 30.0), Vec3::Zero(), Vec3(0, 1, 0), 12, 48, 48);
  o.lod = false;
  o.spp = 1;
  const cv::Mat point = Renderer(mesh, {&set}, o).render(cam);
  o.lod = true;
  const cv::Mat lod = Renderer(mesh, {&set}, o).render(cam);
  o.lod = false;
  o.spp = 64;
  const cv::Mat reference = Renderer(mesh, {&set}, o).render(cam);
  int n = 0;
  LodErrors e;
  e.point = interior_rms(point, reference, &n);
  e.lod = interior_rms(lod, reference, &n);
  EXPECT_GT(n, 100);
  return e;
}

struct Stats {
  double max_abs = 0, mean_abs = 0;
  int n = 0;
};

// A view-independent set (Lambert, normal-warped): both modes give irradiance(n) up to resampling error.
TEST(Renderer, LambertSetGivesTheAnalyticRadianceOfTheHitNormalInBothModes) {
  const Mesh mesh = test_sphere();
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 64, 64, "normal", lambert_texel);
  const Camera cam = look_at(Vec3(1.5, 1.0, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 40, 96, 80);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    const Renderer renderer(mesh, {&set}, with_mode(mode));
    const cv::Mat img = renderer.render(cam);
    Stats s;
    for (int r = 0; r < cam.height; ++r)
      for (int c = 0; c < cam.width; ++c) {
        const PixelHit p = trace(renderer, cam, c, r);
        ASSERT_EQ(img.at<cv::Vec4f>(r, c)[3], p.hit ? 1.f : 0.f);
        if (!p.hit || p.n.dot(p.v) < 0.2 || p.n.dot(cam.view_direction()) < 0.2) continue;
        const double e = (pixel(img, c, r) - irradiance(p.n)).cwiseAbs().maxCoeff();
        s.max_abs = std::max(s.max_abs, e);
        s.mean_abs += e;
        ++s.n;
      }
    ASSERT_GT(s.n, 1000);
    std::printf("lambert %s: max %.3g mean %.3g over %d pixels\n", to_string(mode), s.max_abs, s.mean_abs / s.n, s.n);
    // Measured (64^2 maps): per-pixel max 9.0e-3 mean 4.6e-4; paper max 4.4e-3 mean 2.8e-4. The
    // largest errors are bilinear resampling near the sources' rims, where the fade hands over.
    EXPECT_LT(s.max_abs, 1.5e-2) << to_string(mode);
    EXPECT_LT(s.mean_abs / s.n, 1e-3) << to_string(mode);
  }
}

// A mirror set without Fresnel (view independent in reflection space): per-pixel mode reflects each
// pixel's own view direction; paper mode reflects the camera's central direction (its approximation).
TEST(Renderer, MirrorSetGivesTheAnalyticReflectionPerPixelAndTheCentralOneInPaperMode) {
  const Mesh mesh = test_sphere();
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 128, 128, "mirror", mirror_texel);
  const Camera cam = look_at(Vec3(-1.0, 2.0, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 35, 96, 96);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    const Renderer renderer(mesh, {&set}, with_mode(mode));
    const cv::Mat img = renderer.render(cam);
    Stats s, wrong;  // wrong: against the other mode's analytic answer
    for (int r = 0; r < cam.height; ++r)
      for (int c = 0; c < cam.width; ++c) {
        const PixelHit p = trace(renderer, cam, c, r);
        if (!p.hit || p.n.dot(p.v) < 0.3 || p.n.dot(cam.view_direction()) < 0.3) continue;
        const Vec3 exact = environment(reflect(p.v, p.n)), central = environment(reflect(cam.view_direction(), p.n));
        const Vec3 truth = mode == RenderMode::PerPixel ? exact : central;
        const Vec3 other = mode == RenderMode::PerPixel ? central : exact;
        const double e = (pixel(img, c, r) - truth).cwiseAbs().maxCoeff();
        s.max_abs = std::max(s.max_abs, e);
        s.mean_abs += e;
        wrong.mean_abs += (pixel(img, c, r) - other).cwiseAbs().maxCoeff();
        ++s.n;
      }
    ASSERT_GT(s.n, 1000);
    std::printf("mirror %s: max %.3g mean %.3g, other mode mean %.3g\n", to_string(mode), s.max_abs, s.mean_abs / s.n,
                wrong.mean_abs / s.n);
    // Measured (128^2 maps): per-pixel max 7.2e-3, paper 1.3e-3, both mean 2.3e-4; against the other
    // mode's answer the mean error is 6.2e-2 (35 degree field of view).
    EXPECT_LT(s.max_abs, 2e-2) << to_string(mode);
    EXPECT_LT(s.mean_abs / s.n, 1e-3) << to_string(mode);
    // The test can tell the modes apart: the other mode's answer is measurably worse.
    EXPECT_GT(wrong.mean_abs, 3 * s.mean_abs) << to_string(mode);
  }
}

// The paper's approximation shades every pixel as seen from the image centre: its error against the
// exact reflection grows with the field of view (the sphere framed alike), per-pixel mode's does not.
TEST(Renderer, PaperModeErrorGrowsWithTheFieldOfView) {
  const Mesh mesh = test_sphere();
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 128, 128, "mirror", mirror_texel);
  const Eigen::AlignedBox3f box(Eigen::Vector3f(-1, -1, -1), Eigen::Vector3f(1, 1, 1));
  double paper[2], exact[2];
  const double fovs[2] = {5, 50};
  for (int f = 0; f < 2; ++f) {
    const Camera cam = frame_bounds(box, Vec3(-0.2, -0.4, -1), Vec3(0, 1, 0), fovs[f], 80, 80);
    for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
      const Renderer renderer(mesh, {&set}, with_mode(mode));
      const cv::Mat img = renderer.render(cam);
      double sum = 0;
      int n = 0;
      for (int r = 0; r < cam.height; ++r)
        for (int c = 0; c < cam.width; ++c) {
          const PixelHit p = trace(renderer, cam, c, r);
          if (!p.hit || p.n.dot(p.v) < 0.3) continue;
          sum += (pixel(img, c, r) - environment(reflect(p.v, p.n))).cwiseAbs().maxCoeff();
          ++n;
        }
      ASSERT_GT(n, 1000);
      (mode == RenderMode::Paper ? paper : exact)[f] = sum / n;
    }
  }
  std::printf("mean error against the exact reflection, fov 5 / 50 degrees: paper %.3g / %.3g, per-pixel %.3g / %.3g\n",
              paper[0], paper[1], exact[0], exact[1]);
  EXPECT_GT(paper[1], 4 * paper[0]);
  EXPECT_GT(paper[1], 10 * exact[1]);
  EXPECT_LT(exact[1], 1e-3);
  EXPECT_LT(exact[0], 1e-3);
}

// Far away with a tiny field of view, the centre pixel's view direction is the camera's: the modes
// agree to float precision (odd map size: the disc centre, where n = v lands, is a texel centre).
TEST(Renderer, BothModesAgreeAtTheCentrePixelOfAFarNarrowCamera) {
  const ViewSet views = ViewSet::icosahedron();
  const MapSet set = analytic_map_set(views, 32, 32, "mirror", fresnel_mirror_texel);
  for (const Vec3& v : {Vec3(0.3, 0.5, 0.8).normalized(), Vec3(-0.7, 0.1, -0.2).normalized()}) {
    const Mesh mesh = quad_mesh(v, 1.0);
    const Camera cam = look_at(1000.0 * v, Vec3::Zero(), Vec3(0, 1, 0), 0.01, 33, 33);
    const cv::Mat a = Renderer(mesh, {&set}, with_mode(RenderMode::PerPixel)).render(cam);
    const cv::Mat b = Renderer(mesh, {&set}, with_mode(RenderMode::Paper, 33)).render(cam);
    const Vec3 pa = pixel(a, 16, 16), pb = pixel(b, 16, 16);
    ASSERT_EQ(a.at<cv::Vec4f>(16, 16)[3], 1.f);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(pa[k], pb[k], 1e-5 * std::max(1.0, std::abs(pa[k])));
    // ... and both are the lookup at (v, v).
    const BlendEngine lookup(set, views);
    const Vec3 L = lookup.radiance(v, v);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(pa[k], L[k], 1e-5);
  }
}

// A set covering only the upper hemisphere, seen from below (view outside the set), silhouettes with
// grazing normals, supersampling: every value finite, alpha in [0, 1].
TEST(Renderer, NoNanOrInfAtSilhouettesAndOutsideANonSurroundingSet) {
  std::vector<Vec3> up;
  const ViewSet all = ViewSet::geodesic(1);  // named: views() refers into it
  for (const Vec3& v : all.views())
    if (v.y() > 0.3) up.push_back(v);
  const MapSet set = analytic_map_set(ViewSet(up), 32, 32, "mirror", fresnel_mirror_texel);
  Mesh mesh = test_sphere(24, 48);
  // A second, open shape (a quad seen from behind) to get back faces.
  const Mesh quad = quad_mesh(Vec3(1, 0, 0), 1.5);
  const uint32_t base = uint32_t(mesh.positions.size());
  for (std::size_t i = 0; i < quad.positions.size(); ++i) {
    mesh.positions.push_back(quad.positions[i] + Eigen::Vector3f(0, 0, 1.5f));
    mesh.normals.push_back(quad.normals[i]);
  }
  for (const auto& t : quad.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const Camera cam = look_at(Vec3(0.5, -3.0, 1.5), Vec3::Zero(), Vec3(0, 1, 0), 60, 64, 48);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    for (int spp : {1, 4}) {
      RenderOptions o = with_mode(mode);
      o.spp = spp;
      RenderStats stats;
      const cv::Mat img = Renderer(mesh, {&set}, o).render(cam, &stats);
      EXPECT_GT(stats.hits, 0);
      int fractional = 0;
      for (int r = 0; r < img.rows; ++r)
        for (int c = 0; c < img.cols; ++c) {
          const cv::Vec4f p = img.at<cv::Vec4f>(r, c);
          for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(p[k])) << to_string(mode) << " " << c << "," << r;
          ASSERT_GE(p[3], 0.f);
          ASSERT_LE(p[3], 1.f);
          fractional += p[3] > 0 && p[3] < 1;
        }
      if (spp == 4)
        EXPECT_GT(fractional, 10) << "supersampling gives partial coverage at silhouettes";
      else
        EXPECT_EQ(fractional, 0);
    }
  }
}

// Multi-lobe maps: rendering two sets at once is the sum of rendering each.
TEST(Renderer, SummingTwoMapSetsEqualsTheSumOfSeparateRenders) {
  const Mesh mesh = test_sphere(24, 48);
  const MapSet a = analytic_map_set(ViewSet::icosahedron(), 32, 32, "normal", lambert_texel);
  const MapSet b = analytic_map_set(ViewSet::geodesic(1), 48, 48, "mirror", fresnel_mirror_texel);
  const Camera cam = look_at(Vec3(2.0, 1.0, 2.5), Vec3::Zero(), Vec3(0, 1, 0), 45, 64, 48);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    const cv::Mat ra = Renderer(mesh, {&a}, with_mode(mode, 40)).render(cam);
    const cv::Mat rb = Renderer(mesh, {&b}, with_mode(mode, 40)).render(cam);
    const cv::Mat rab = Renderer(mesh, {&a, &b}, with_mode(mode, 40)).render(cam);
    for (int r = 0; r < cam.height; ++r)
      for (int c = 0; c < cam.width; ++c) {
        const cv::Vec4f pa = ra.at<cv::Vec4f>(r, c), pb = rb.at<cv::Vec4f>(r, c), pab = rab.at<cv::Vec4f>(r, c);
        for (int k = 0; k < 3; ++k)
          ASSERT_NEAR(pab[k], pa[k] + pb[k], 1e-6 * (1 + std::abs(pab[k]))) << to_string(mode);
        ASSERT_EQ(pab[3], pa[3]);
      }
  }
}

TEST(Renderer, RenderDoesNotDependOnTheThreadCount) {
  const Mesh mesh = test_sphere(24, 48);
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 32, 32, "mirror", fresnel_mirror_texel);
  const Camera cam = look_at(Vec3(0.4, 0.3, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 50, 80, 60);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    const Renderer renderer(mesh, {&set}, with_mode(mode));
    const cv::Mat many = renderer.render(cam);
    cv::Mat one;
    {
      tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
      one = renderer.render(cam);
    }
    EXPECT_EQ(cv::norm(many, one, cv::NORM_INF), 0.0) << to_string(mode);
  }
}

// A kept frame buffer (a turntable's): rendering into it reuses its memory and gives each frame
// exactly what a fresh render gives, with nothing of the previous frame left (here a frame where the
// sphere covers other pixels, then one of another size).
TEST(Renderer, RenderingIntoAKeptBufferEqualsAFreshRenderAndReusesIt) {
  const Mesh mesh = test_sphere(24, 48);
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 32, 32, "mirror", fresnel_mirror_texel);
  const Camera a = look_at(Vec3(0.4, 0.3, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 50, 80, 60);
  const Camera b = look_at(Vec3(-2.5, 1.0, 4.0), Vec3(0.6, 0, 0), Vec3(0, 1, 0), 30, 80, 60);
  const Camera c = look_at(Vec3(0.4, 0.3, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 50, 40, 30);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    const Renderer renderer(mesh, {&set}, with_mode(mode));
    cv::Mat kept;
    renderer.render(a, kept);
    EXPECT_EQ(cv::norm(kept, renderer.render(a), cv::NORM_INF), 0.0) << to_string(mode);
    const uchar* data = kept.data;
    renderer.render(b, kept);
    EXPECT_EQ(kept.data, data) << to_string(mode);  // the same buffer
    const cv::Mat fresh = renderer.render(b);
    EXPECT_GT(cv::norm(fresh, renderer.render(a), cv::NORM_INF), 0.0);  // the frames differ
    EXPECT_EQ(cv::norm(kept, fresh, cv::NORM_INF), 0.0) << to_string(mode);
    renderer.render(c, kept);
    ASSERT_EQ(kept.size(), cv::Size(40, 30));
    EXPECT_EQ(cv::norm(kept, renderer.render(c), cv::NORM_INF), 0.0) << to_string(mode);
  }
}

TEST(Renderer, MissesAreBlackWithAlphaZeroOrTheEnvironment) {
  const Mesh mesh = test_sphere(12, 24);
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 16, 16, "normal", lambert_texel);
  const Camera cam = look_at(Vec3(0, 0, 6), Vec3::Zero(), Vec3(0, 1, 0), 40, 32, 32);
  const cv::Mat plain = Renderer(mesh, {&set}).render(cam);
  EXPECT_EQ(plain.at<cv::Vec4f>(0, 0), cv::Vec4f(0, 0, 0, 0));
  EXPECT_EQ(plain.at<cv::Vec4f>(16, 16)[3], 1.f);
  EnvMap env = EnvMap::zeros(Layout::with_size(LayoutKind::LatLong, 64));
  env.pixels.setTo(cv::Scalar(0.25, 0.5, 2.0));
  RenderOptions o;
  o.environment = &env;
  const cv::Mat shown = Renderer(mesh, {&set}, o).render(cam);
  const cv::Vec4f corner = shown.at<cv::Vec4f>(0, 0);
  EXPECT_NEAR(corner[0], 0.25, 1e-6);
  EXPECT_NEAR(corner[2], 2.0, 1e-6);
  EXPECT_EQ(corner[3], 1.f);
  EXPECT_EQ(shown.at<cv::Vec4f>(16, 16), plain.at<cv::Vec4f>(16, 16));
}

// Per-pixel mode with lookups at each pixel's level of detail (RenderOptions::lod): a sphere a few
// pixels across in a set of fine detail. One tap per source aliases; the footprint's MIP levels bring
// each pixel close to the pixel's mean, which a 64-sample supersampled render estimates.
TEST(Renderer, LodBringsASmallObjectCloserToItsSupersampledSelf) {
  const MapSet set = checker_set("mirror", mirror_texel);
  const LodErrors e = small_sphere_lod_errors(set, test_sphere(24, 48), RenderOptions{});
  std::printf("rms point %.4f lod %.4f\n", e.point, e.lod);
  EXPECT_LT(e.lod, std::sqrt(0.5) * e.point) << "rms point " << e.point << ", lod " << e.lod;
}

// Paper mode with --lod: the frame's one destination map is read at each sample's footprint level,
// so a small object comes closer to its supersampled self there too; on a large object (footprints
// under a texel) the lookup stays the plain tap's value.
TEST(Renderer, PaperModeLodBringsASmallObjectCloserToItsSupersampledSelf) {
  const MapSet set = checker_set("normal", lambert_texel);
  const Mesh mesh = test_sphere(24, 48);
  RenderOptions o = with_mode(RenderMode::Paper);
  {  // small: about 18 pixels across
    const LodErrors e = small_sphere_lod_errors(set, mesh, o);
    std::printf("paper: rms point %.4f lod %.4f\n", e.point, e.lod);
    EXPECT_LT(e.lod, std::sqrt(0.5) * e.point) << "rms point " << e.point << ", lod " << e.lod;
  }
  {  // large: the sphere fills most of the frame, a pixel spans about half a texel
    const Camera cam = look_at(Vec3(0.5, 0.8, 3.2), Vec3::Zero(), Vec3(0, 1, 0), 40, 256, 256);
    const cv::Mat point = Renderer(mesh, {&set}, o).render(cam);
    o.lod = true;
    const cv::Mat lod = Renderer(mesh, {&set}, o).render(cam);
    int n = 0;
    const double e = interior_rms(lod, point, &n);
    std::printf("paper, large: rms lod against point %.2e\n", e);
    EXPECT_LT(e, 0.01) << "a footprint under a texel should read about the plain tap";
    ASSERT_GT(n, 1000);
  }
}

TEST(Renderer, RejectsBadOptions) {
  const Mesh mesh = test_sphere(8, 16);
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 16, 16, "normal", lambert_texel);
  RenderOptions o;
  o.spp = 2;
  EXPECT_THROW(Renderer(mesh, {&set}, o), std::invalid_argument);
  o = with_mode(RenderMode::Paper);
  o.warp = "fancy";
  EXPECT_THROW(Renderer(mesh, {&set}, o), std::invalid_argument);
  EXPECT_THROW(Renderer(mesh, {}, RenderOptions{}), std::invalid_argument);
  EXPECT_THROW(render_mode_from_string("fast"), std::invalid_argument);
}

// The packet path the renderer traces with finds what single rays find.
TEST(Renderer, PacketHitsMatchSingleRays) {
  const Mesh mesh = test_sphere(16, 32);
  const RayScene scene(mesh);
  const Camera cam = look_at(Vec3(0.3, 0.2, 3.0), Vec3::Zero(), Vec3(0, 1, 0), 45, 61, 47);
  std::vector<Vec3> dirs;
  for (int r = 0; r < cam.height; ++r)
    for (int c = 0; c < cam.width; ++c) dirs.push_back(cam.ray_direction(c, r));
  std::vector<RayHit> hits(dirs.size());
  scene.intersect_coherent(cam.eye, dirs.data(), int(dirs.size()), hits.data());
  int hit = 0, same_triangle = 0;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const RayHit one = scene.intersect(cam.eye, dirs[i]);
    ASSERT_EQ(hits[i].hit, one.hit) << i;
    if (!one.hit) continue;
    ++hit;
    same_triangle += hits[i].triangle == one.triangle;
    EXPECT_NEAR(hits[i].t, one.t, 1e-5);
  }
  EXPECT_GT(hit, 500);
  EXPECT_GE(same_triangle, hit - 2);
}

TEST(Renderer, RendersTheBunny) {
  const std::string path = std::string(RSIBR_CACHE_DIR) + "/assets/models/bunny.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent (scripts fetch it into cache/)";
  const Mesh mesh = load_mesh(path);
  const MapSet set = analytic_map_set(ViewSet::icosahedron(), 32, 32, "mirror", fresnel_mirror_texel);
  const Vec3 centre = mesh.bounds().center().cast<double>();
  const Camera cam = frame_bounds(mesh.bounds(), Vec3(0, -0.3, -1), Vec3(0, 1, 0), 40, 160, 90);
  for (RenderMode mode : {RenderMode::PerPixel, RenderMode::Paper}) {
    RenderStats stats;
    const cv::Mat img = Renderer(mesh, {&set}, with_mode(mode)).render(cam, &stats);
    EXPECT_GT(stats.hits, 1000) << to_string(mode);
    EXPECT_EQ(stats.hits, stats.covered_pixels);
    EXPECT_TRUE(cv::checkRange(img)) << to_string(mode);
    Vec2 px;
    ASSERT_TRUE(cam.project(centre, &px));
  }
}

}  // namespace
}  // namespace rsibr
