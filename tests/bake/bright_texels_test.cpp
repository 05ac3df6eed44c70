// The sun split (bake/bright_texels.h): exact bookkeeping, clusters that keep the power, and a
// quadrature that agrees with the reference over the bright texels.
#include "tests/bake/integrator_cases.h"

#include "bake/bright_texels.h"
#include "bake/brdf_spec.h"
#include "bake/reference_integrator.h"
#include "bake/shading_frame.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

EnvMap sunny_env() { return test::latlong_env(test::sunny_radiance(1e5), 128, 8); }

TEST(BrightTexels, RemainderPlusBrightTexelsIsTheEnvironmentExactly) {
  const EnvMap env = sunny_env();
  const EnvironmentSplit split = split_bright_texels(env);
  ASSERT_FALSE(split.bright.empty());
  EXPECT_GT(split.bright_share, 0.5);  // the 1e5 sun dominates
  cv::Mat sum = split.remainder.pixels.clone();
  const int w = env.layout.width();
  for (const BrightTexel& b : split.bright) {
    cv::Vec3f& p = sum.at<cv::Vec3f>(int(b.texel / w), int(b.texel % w));
    EXPECT_EQ(p, cv::Vec3f(0, 0, 0));
    p = cv::Vec3f(float(b.radiance[0]), float(b.radiance[1]), float(b.radiance[2]));
  }
  EXPECT_EQ(cv::norm(sum, env.pixels, cv::NORM_INF), 0.0);
}

TEST(BrightTexels, ClustersKeepThePowerAndTheirRadius) {
  const EnvironmentSplit split = split_bright_texels(sunny_env());
  Vec3 total = Vec3::Zero();
  for (const BrightTexel& b : split.bright) total += b.radiance * b.solid_angle;
  ASSERT_EQ(split.levels.size(), 6u);
  std::size_t previous = split.bright.size() + 1;
  for (const BrightClusterLevel& level : split.levels) {
    Vec3 sum = Vec3::Zero();
    for (const BrightCluster& c : level.clusters) {
      sum += c.power;
      EXPECT_LE(c.radius, 2 * level.max_radius + 1e-12);  // members within r of the seed
      EXPECT_NEAR(c.dir.norm(), 1.0, 1e-12);
    }
    EXPECT_LT((sum - total).norm(), 1e-12 * total.norm());
    EXPECT_LE(level.clusters.size(), previous);  // coarser levels never have more clusters
    previous = level.clusters.size();
  }
}

TEST(BrightTexels, DisabledSplitLeavesTheEnvironment) {
  const EnvMap env = sunny_env();
  const EnvironmentSplit split = split_bright_texels(env, {0.0, 64});
  EXPECT_TRUE(split.bright.empty());
  EXPECT_EQ(cv::norm(split.remainder.pixels, env.pixels, cv::NORM_INF), 0.0);
}

// Over an environment holding only the bright texels, the split's first term equals the reference
// quadrature: exactly where the level is single texels (narrow lobe), to the O((rho/width)^2)
// clustering error for wide lobes.
TEST(BrightTexels, QuadratureAgreesWithTheReferenceOverTheBrightTexels) {
  const EnvMap env = sunny_env();
  const EnvironmentSplit split = split_bright_texels(env);
  EnvMap only = env;
  only.pixels = env.pixels - split.remainder.pixels;
  const auto reference = make_integrator("reference", only);
  const Vec3 view = Vec3(0.2, 0.3, 1).normalized();
  const Mat3 T = world_from_view_for(view);
  const std::pair<const char*, double> cases[] = {
      {"{type: lambert, albedo: [0.5, 0.6, 0.7]}", 2e-3},
      {"{type: ggx, roughness: 0.2, fresnel: {type: schlick, f0: [0.9, 0.6, 0.3]}}", 5e-3},
      {"{type: ggx, roughness: 0.05, fresnel: {type: none}}", 1e-9},
  };
  for (const auto& [spec, tolerance] : cases) {
    const auto brdf = parse_brdf(spec);
    const int size = 24;
    const cv::Mat ref = reference->radiance_map(*brdf, view, T, size, {});
    cv::Mat got(size, size, CV_32FC3, cv::Scalar::all(0));
    for (int r = 0; r < size; ++r)
      for (int c = 0; c < size; ++c) {
        const auto t = integrator_detail::texel_frame(c, r, size, view, T);
        if (!t) continue;
        const Vec3 L = bright_texel_radiance(*brdf, t->frame, t->wo, split, env.layout);
        got.at<cv::Vec3f>(r, c) = cv::Vec3f(float(L[0]), float(L[1]), float(L[2]));
      }
    const double err = test::relative_rms(got, ref);
    EXPECT_LT(err, tolerance) << spec;
    std::printf("bright quadrature vs reference, %s: rel RMS %.3e\n", spec, err);
  }
}

}  // namespace
}  // namespace rsibr
