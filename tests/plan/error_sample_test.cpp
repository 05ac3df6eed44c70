#include "plan/error_sample.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "core/patterns.h"
#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <set>

namespace rsibr {
namespace {

EnvMap sky(const Vec3& sun) {
  return render_pattern(
      patterns::sun_and_sky(sun.normalized(), 0.08, Vec3(400, 380, 300), Vec3(0.3, 0.5, 1.0), Vec3(0.9, 0.8, 0.6)),
      Layout(LayoutKind::LatLong, 64, 32), 2);
}

TEST(ErrorSample, TexelsAreDistinctInsideTheDiscAndTheSameForTheSameSeed) {
  const ErrorSample a(3, 50, 32, 7), b(3, 50, 32, 7), c(3, 50, 32, 8);
  ASSERT_EQ(a.count(), 150);
  bool differs = false;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a.view(k).norm(), 1.0, 1e-12);
    EXPECT_EQ(a.texels(k), b.texels(k));
    differs = differs || a.texels(k) != c.texels(k);
    const std::set<int> distinct(a.texels(k).begin(), a.texels(k).end());
    EXPECT_EQ(distinct.size(), 50u);
    for (int t : a.texels(k)) EXPECT_LT(sphere_map::disc_from_pixel(Vec2(t % 32, t / 32), 32, 32).squaredNorm(), 1.0);
    EXPECT_EQ(cv::countNonZero(a.mask(k)), 50);
  }
  EXPECT_TRUE(differs);
}

TEST(ErrorSample, MoreTexelsThanTheDiscHoldsAreRefused) {
  EXPECT_THROW(ErrorSample(1, int(disc_texel_count(8)) + 1, 8, 0, 0.0), std::invalid_argument);
  EXPECT_NO_THROW(ErrorSample(1, int(disc_texel_count(8)), 8, 0, 0.0));
  EXPECT_THROW(ErrorSample(1, int(disc_texel_count(8, 0.5)) + 1, 8, 0, 0.5), std::invalid_argument);
  EXPECT_LT(disc_texel_count(64, 0.1), disc_texel_count(64));
  EXPECT_THROW(ErrorSample(1, 1, 8, 0, 1.0), std::invalid_argument);
  EXPECT_EQ(disc_texel_count(2), 4);
  EXPECT_EQ(disc_texel_count(1), 1);
}

TEST(ErrorSample, NormalsAreTheDestinationFramesNormalsAndLeaveOutTheGrazingRing) {
  const ErrorSample s(4, 300, 64, 3);
  double lowest = 1;
  for (int k = 0; k < s.view_count(); ++k)
    for (int t : s.texels(k)) {
      const Vec3 n = s.normal(k, t);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      lowest = std::min(lowest, n.dot(s.view(k)));
    }
  EXPECT_GE(lowest, ErrorSample::kDefaultMinCos - 1e-12);
  EXPECT_LT(lowest, 0.2);  // the sample reaches close to the ring it leaves out
}

// The footprint trick is exact: blending the set baked only where the blend reads gives the blend of
// the whole set, texel for texel (mirror and normal warps, with and without albedo normalisation).
void expect_footprints_equal_the_whole_set(const std::string& spec, bool normalise) {
  const EnvMap env = sky(Vec3(0.3, 0.8, 0.2));
  const auto brdf = parse_brdf(spec);
  const auto integrator = make_integrator("fis", env);
  const ViewSet views = ViewSet::named("42");
  MapSetBakeOptions o;
  o.res = 24;
  o.integrator.samples = 16;
  o.normalise_albedo = normalise;
  const MapSet whole = bake_map_set(*brdf, *integrator, views, o);
  const ErrorSample sample(3, 40, 48, 11);
  const SampledBlend full = sampled_blend(whole, views, sample);
  const SampledBlend sparse = sampled_blend(*integrator, *brdf, o.integrator, views, o.res, normalise, sample);
  ASSERT_EQ(full.values.size(), sparse.values.size());
  for (std::size_t i = 0; i < full.values.size(); ++i) {
    EXPECT_EQ(full.values[i], sparse.values[i]) << spec << " texel " << i;
    EXPECT_EQ(full.weights[i], sparse.weights[i]);
  }
  EXPECT_GT(sparse.texels_baked, 0);
  EXPECT_LT(sparse.texels_baked, 42LL * 24 * 24 / 2);  // a fraction of the set
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetMirrorWarp) {
  expect_footprints_equal_the_whole_set("{type: ggx, roughness: 0.3, fresnel: {type: schlick, f0: [0.9, 0.6, 0.5]}}",
                                        false);
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetNormalWarp) {
  expect_footprints_equal_the_whole_set("{type: lambert, albedo: [0.8, 0.7, 0.6]}", false);
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetAlbedoNormalised) {
  expect_footprints_equal_the_whole_set("{type: ggx, roughness: 0.4, fresnel: {type: schlick, f0: [0.04, 0.04, 0.04]}}",
                                        true);
}

TEST(SampledBlend, ABlendAtItsOwnViewsIsTheDirectBake) {
  // Novel views that are the set's views: the blend returns each source, so the error is float
  // rounding alone.
  const EnvMap env = sky(Vec3(-0.2, 0.5, 0.8));
  const auto brdf = parse_brdf("{type: lambert, albedo: [0.5, 0.5, 0.5]}");
  const auto integrator = make_integrator("reference", env);
  const ErrorSample sample(2, 30, 32, 5);
  std::vector<Vec3> own;
  for (int k = 0; k < sample.view_count(); ++k) own.push_back(sample.view(k));
  own.push_back(Vec3(0, 1, 0));
  own.push_back(Vec3(0, -1, 0));
  own.push_back(Vec3(1, 0, 0));
  own.push_back(Vec3(-1, 0, 0.1));
  const ViewSet views(own);
  IntegratorOptions o;
  const std::vector<Vec3> direct = direct_values(*integrator, *brdf, o, sample);
  const SampledBlend b = sampled_blend(*integrator, *brdf, o, views, 32, false, sample);
  EXPECT_LT(relative_rms(b.values, direct, &b.weights), 1e-5);
}

TEST(RelativeRms, IsZeroForEqualVectorsAndScalesWithTheError) {
  const std::vector<Vec3> truth = {Vec3(1, 2, 3), Vec3(0, 1, 0)};
  EXPECT_EQ(relative_rms(truth, truth), 0.0);
  std::vector<Vec3> off = truth;
  for (Vec3& v : off) v *= 1.1;
  EXPECT_NEAR(relative_rms(off, truth), 0.1, 1e-12);
  const std::vector<double> weights = {0.0, 1.0};
  off[0] = Vec3(100, 100, 100);  // weight 0: left out
  EXPECT_NEAR(relative_rms(off, truth, &weights), 0.1, 1e-12);
  EXPECT_EQ(relative_rms({Vec3(0, 0, 0)}, {Vec3(0, 0, 0)}), 0.0);
  EXPECT_TRUE(std::isinf(relative_rms({Vec3(1, 0, 0)}, {Vec3(0, 0, 0)})));
  EXPECT_THROW(relative_rms(truth, {Vec3(1, 1, 1)}), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
