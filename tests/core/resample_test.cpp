// Resampling between layouts and the MIP pyramid.
#include "core/resample.h"

#include "formats/exr_io.h"
#include "core/mip_pyramid.h"
#include "core/patterns.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace rsibr {
namespace {

std::vector<Layout> targets() {
  return {Layout::with_size(LayoutKind::LatLong, 256), Layout::with_size(LayoutKind::Cube, 64),
          Layout::with_size(LayoutKind::Octahedral, 128), Layout::with_size(LayoutKind::Sphere, 128),
          Layout::with_size(LayoutKind::Sphere, 31)};
}

double max_relative_change(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::abs(a[k] - b[k]) / std::abs(a[k]));
  return worst;
}

TEST(Resample, ConstantEnvironmentStaysConstantInEveryLayout) {
  for (const Layout& from : targets()) {
    const EnvMap src = render_pattern(patterns::constant(Vec3(1.7, 0.2, 30)), from, 1);
    for (const Layout& to : targets()) {
      const EnvMap out = resample(src, to);
      for (int r = 0; r < to.height(); ++r)
        for (int c = 0; c < to.width(); ++c) {
          const float* p = out.pixels.ptr<float>(r) + 3 * c;
          if (to.texel_solid_angle(c, r) == 0) {
            EXPECT_EQ(p[0], 0.f);  // outside a sphere map's disc
            continue;
          }
          ASSERT_NEAR(p[0], 1.7f, 2e-6f) << to_string(from.kind()) << "->" << to_string(to.kind()) << " " << c << ","
                                         << r;
          ASSERT_NEAR(p[2], 30.f, 4e-5f);
        }
    }
  }
}

TEST(Resample, IntegralOfAnalyticEnvironmentsIsKept) {
  // Direction-coded: integral 2*pi per channel. Sun and sky: a 0.5-degree sun 1e5 times the sky.
  const Vec3 sun_dir = Vec3(0.3, 0.6, -0.5).normalized();
  const double sun_r = 0.5 * kPi / 180;
  const auto sky = patterns::sun_and_sky(sun_dir, sun_r, Vec3(1e5, 9e4, 8e4), Vec3(0.3, 0.5, 1.0), Vec3(0.8, 0.8, 0.7));
  for (const Layout& from : {Layout::with_size(LayoutKind::LatLong, 512), Layout::with_size(LayoutKind::Cube, 128)}) {
    const EnvMap coded = render_pattern(patterns::direction_coded(), from, 2);
    const EnvMap sunny = render_pattern(sky, from, 6);
    for (const Layout& to : targets()) {
      EXPECT_LT(max_relative_change(integral(coded), integral(resample(coded, to))), 1e-3)
          << to_string(from.kind()) << "->" << to_string(to.kind());
      EXPECT_LT(max_relative_change(integral(sunny), integral(resample(sunny, to))), 1e-3)
          << "sun: " << to_string(from.kind()) << "->" << to_string(to.kind());
    }
  }
}

TEST(Resample, ShrinkingIsAreaWeightedAndDoesNotAlias) {
  // A 1-degree checker shrunk to coarser layouts must equal the checker's exact average over each
  // output texel (rendered analytically with 24 x 24 points per texel); one bilinear tap per texel
  // (point sampling) aliases and misses it by far more.
  const auto checker = patterns::latlong_checker(1.0);
  const EnvMap fine = render_pattern(checker, Layout::with_size(LayoutKind::LatLong, 2048), 1);
  for (const Layout& to : targets()) {
    const EnvMap truth = render_pattern(checker, to, 24);
    const EnvMap area = resample(fine, to);
    ResampleOptions point;
    point.supersampling = 1e-3;  // forces n = 1: one bilinear tap per texel
    const EnvMap aliased = resample(fine, to, point);
    double err_area = 0, err_point = 0;
    long n = 0;
    for (int r = 0; r < to.height(); ++r)
      for (int c = 0; c < to.width(); ++c) {
        const auto d = to.direction(Vec2(c, r));
        if (!d || std::abs(d->y()) > 0.95) continue;  // the 2048 source cannot resolve the checker at the poles
        const float t = truth.pixels.at<cv::Vec3f>(r, c)[0];
        err_area += std::pow(area.pixels.at<cv::Vec3f>(r, c)[0] - t, 2);
        err_point += std::pow(aliased.pixels.at<cv::Vec3f>(r, c)[0] - t, 2);
        ++n;
      }
    const double rms_area = std::sqrt(err_area / n), rms_point = std::sqrt(err_point / n);
    std::printf("  %-10s %4dx%-4d rms error: area-weighted %.4f, point-sampled %.4f\n", to_string(to.kind()).c_str(),
                to.width(), to.height(), rms_area, rms_point);
    EXPECT_LT(rms_area, 0.03) << to_string(to.kind());  // the bilinear source blurs the checker's edges a little
    EXPECT_GT(rms_point, 5 * rms_area) << to_string(to.kind());
  }
}

TEST(Resample, InterpolatedTapsAgreeWithExactTapsFromLatLong) {
  // A sun (the energy rule's exact texels), a seam crossing, the poles and a sphere map's rim.
  const auto sky = patterns::sun_and_sky(Vec3(-0.05, 0.3, -1).normalized(), 1.0 * kPi / 180, Vec3(3e4, 3e4, 2e4),
                                         Vec3(0.3, 0.5, 1.0), Vec3(0.8, 0.8, 0.7));
  const EnvMap src = render_pattern(sky, Layout::with_size(LayoutKind::LatLong, 512), 4);
  ResampleOptions exact_taps;
  exact_taps.interpolate_taps = false;
  for (const Layout& to : targets()) {
    const EnvMap fast = resample(src, to), exact = resample(src, to, exact_taps);
    double worst = 0, sum2 = 0, ref2 = 0;
    for (int r = 0; r < to.height(); ++r)
      for (int c = 0; c < to.width(); ++c) {
        const cv::Vec3f a = fast.pixels.at<cv::Vec3f>(r, c), b = exact.pixels.at<cv::Vec3f>(r, c);
        ASSERT_TRUE(std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]));
        worst = std::max(worst, double(cv::norm(a - b)) / std::max(1.0, double(cv::norm(b))));
        sum2 += cv::norm(a - b) * cv::norm(a - b);
        ref2 += cv::norm(b) * cv::norm(b);
      }
    EXPECT_LT(worst, 0.05) << to_string(to.kind());
    EXPECT_LT(std::sqrt(sum2 / ref2), 2e-3) << to_string(to.kind());
    EXPECT_LT(max_relative_change(integral(exact), integral(fast)), 1e-4) << to_string(to.kind());
  }
}

TEST(Resample, EnlargingIsPlainBilinear) {
  const EnvMap small = render_pattern(patterns::direction_coded(), Layout::with_size(LayoutKind::LatLong, 32), 2);
  const Layout big = Layout::with_size(LayoutKind::LatLong, 256);
  const EnvMap out = resample(small, big);
  // Within 45 degrees of the equator the 32-wide source's texels are over 4 output texels wide in
  // every direction (near the poles its columns converge and the footprint is a shrink).
  for (int r = big.height() / 4; r < 3 * big.height() / 4; r += 7)
    for (int c = 0; c < big.width(); c += 5) {
      float expect[3];
      sample_bilinear(small, *big.direction(Vec2(c, r)), expect);
      EXPECT_EQ(out.pixels.at<cv::Vec3f>(r, c)[1], expect[1]);
    }
}

TEST(Resample, SamplingIsContinuousAcrossSeamsFoldsAndTheRim) {
  // A smooth environment sampled either side of every seam differs only by its smoothness.
  const auto f = patterns::direction_coded();
  for (const Layout& L : targets()) {
    const EnvMap map = render_pattern(f, L, 1);
    const double texel = std::sqrt(4 * kPi / L.texel_count());
    std::vector<Vec3> probes = {Vec3(0, 0, -1), Vec3(0, 1, 0),   Vec3(0, -1, 0),  Vec3(1, 1, 0),
                                Vec3(1, 1, 1),  Vec3(-1, -1, 1), Vec3(1, -1, -1), Vec3(0.5, -0.2, -1)};
    std::mt19937 rng(2);
    std::normal_distribution<double> n;
    for (const Vec3& p0 : probes)
      for (int i = 0; i < 20; ++i) {
        const Vec3 p = p0.normalized();
        const Vec3 q = (p + 1e-7 * Vec3(n(rng), n(rng), n(rng))).normalized();
        float a[3], b[3];
        sample_bilinear(map, p, a);
        sample_bilinear(map, q, b);
        for (int k = 0; k < 3; ++k) {
          ASSERT_TRUE(std::isfinite(a[k]) && std::isfinite(b[k]));
          // Sphere maps pack everything near -Z into the rim: allow a few texels of change there.
          const double slack = L.kind() == LayoutKind::Sphere && p.z() < -0.99 ? 0.6 : 1e-3;
          EXPECT_NEAR(a[k], b[k], slack) << to_string(L.kind()) << " near " << p0.transpose();
        }
        // And the value is the environment's, to within a texel's variation.
        const double slack = L.kind() == LayoutKind::Sphere && p.z() < -0.99 ? 1.0 : 2 * texel;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], f(p)[k], slack) << to_string(L.kind()) << " " << p0.transpose();
      }
  }
}

TEST(Resample, RoundTripThroughEveryLayoutKeepsTheIntegralOfRealEnvironments) {
  auto files = testing::real_environments();
  if (files.empty()) GTEST_SKIP() << testing::kNoAssets;
  // Six of the eighteen maps: the suns and point lights (sky, park, night, esplanade), fine foliage
  // (forest) and soft boxes (studio). The property is the same for every map and each costs seconds
  // of CI time; all eighteen once gave at most the error checked here.
  std::erase_if(files, [](const auto& f) {
    const auto s = f.stem().string();
    return s != "sky" && s != "park" && s != "night" && s != "esplanade" && s != "forest" && s != "studio";
  });
  for (const auto& file : files) {
    const EnvMap ll = read_environment(file.string());
    const EnvMap cube = resample(ll, Layout::with_size(LayoutKind::Cube, 148));
    const EnvMap octa = resample(cube, Layout::with_size(LayoutKind::Octahedral, 362));
    const EnvMap sphere = resample(octa, Layout::with_size(LayoutKind::Sphere, 409));
    const EnvMap back = resample(sphere, ll.layout);
    const double err = max_relative_change(integral(ll), integral(back));
    RecordProperty(file.stem().string(), std::to_string(err));
    std::printf("  %-10s latlong->cube->octahedral->sphere->latlong integral change %.2e\n", file.stem().c_str(), err);
    EXPECT_LT(err, 1e-3) << file;
  }
}

TEST(MipPyramid, NestedLevelsKeepTheEnergyExactly) {
  // Sizes that nest from the start: every level has level 0's energy to rounding.
  const auto sky =
      patterns::sun_and_sky(Vec3(0.2, 0.5, 0.6), 0.01, Vec3(5e3, 5e3, 5e3), Vec3(0.2, 0.4, 1), Vec3(1, 1, 1));
  for (const Layout& L : {Layout(LayoutKind::LatLong, 257, 129), Layout::with_size(LayoutKind::Cube, 65),
                          Layout::with_size(LayoutKind::Octahedral, 128), Layout::with_size(LayoutKind::Sphere, 128)}) {
    const EnvMap base = render_pattern(sky, L, 4);
    const MipPyramid pyr(base);
    EXPECT_GE(pyr.levels(), 6) << to_string(L.kind());
    const auto ref = integral(base);
    for (int i = 1; i < pyr.levels(); ++i) {
      EXPECT_LE(pyr.level(i).layout.texel_count() * 2, pyr.level(i - 1).layout.texel_count()) << to_string(L.kind());
      EXPECT_LT(max_relative_change(ref, integral(pyr.level(i))), 1e-6) << to_string(L.kind()) << " level " << i;
    }
  }
}

TEST(MipPyramid, UnnestedBaseIsResampledOnceThenReducedExactly) {
  const auto sky =
      patterns::sun_and_sky(Vec3(0.2, 0.5, 0.6), 0.01, Vec3(5e3, 5e3, 5e3), Vec3(0.2, 0.4, 1), Vec3(1, 1, 1));
  for (const Layout& L : {Layout::with_size(LayoutKind::LatLong, 256), Layout::with_size(LayoutKind::Cube, 64),
                          Layout::with_size(LayoutKind::Octahedral, 90), Layout::with_size(LayoutKind::Sphere, 100)}) {
    const MipPyramid pyr(render_pattern(sky, L, 4));
    ASSERT_GE(pyr.levels(), 4);
    const auto first = integral(pyr.level(1));
    EXPECT_LT(max_relative_change(integral(pyr.level(0)), first), 1e-3) << to_string(L.kind());
    for (int i = 2; i < pyr.levels(); ++i)
      EXPECT_LT(max_relative_change(first, integral(pyr.level(i))), 1e-6)
          << to_string(L.kind()) << " level " << i << " " << pyr.level(i).layout.width() << "x"
          << pyr.level(i).layout.height();
  }
}

TEST(MipPyramid, TrilinearLookupBlendsLevels) {
  const EnvMap base = render_pattern(patterns::direction_coded(), Layout::with_size(LayoutKind::Cube, 32), 2);
  const MipPyramid pyr(base);
  const Vec3 d = Vec3(0.3, -0.4, 0.8).normalized();
  float l0[3], l1[3], mid[3], beyond[3];
  pyr.sample(d, 0.0, l0);
  pyr.sample(d, 1.0, l1);
  pyr.sample(d, 0.5, mid);
  pyr.sample(d, 1e9, beyond);  // clamped to the last level, never out of range
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mid[k], 0.5f * (l0[k] + l1[k]), 1e-6f);
    EXPECT_TRUE(std::isfinite(beyond[k]));
  }
  float nan_lod[3];
  pyr.sample(d, std::nan(""), nan_lod);
  EXPECT_EQ(nan_lod[0], l0[0]);
}

}  // namespace
}  // namespace rsibr
