// The environment sampler of the MIS integrator: its samples follow its own probabilities
// (texel-histogram chi-square), land in the texel they claim, and its pdf is P/Omega.
#include "tests/bake/chi2.h"
#include "tests/bake/integrator_cases.h"

#include "bake/environment_distribution.h"
#include "bake/integrator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rsibr::test {
namespace {

// Texel-histogram chi-square: N samples, expected N P(texel), cells expecting < 5 pooled.
double texel_chi2_p_value(const EnvironmentDistribution& d, long n, std::uint64_t seed, long* mismatched) {
  const long texels = d.layout().texel_count();
  std::vector<double> counts(std::size_t(texels), 0.0);
  integrator_detail::TexelRng rng(seed, 0);
  *mismatched = 0;
  for (long i = 0; i < n; ++i) {
    const auto s = d.sample(rng.uniform2());
    const long t = d.texel_of(s.dir);
    if (t != s.texel) ++*mismatched;
    counts[std::size_t(t)] += 1;
  }
  double chi2 = 0, pooled_obs = 0, pooled_exp = 0;
  int cells = 0;
  for (long t = 0; t < texels; ++t) {
    const double e = n * d.probability(t);
    if (e < 5) {
      pooled_obs += counts[std::size_t(t)];
      pooled_exp += e;
      continue;
    }
    chi2 += (counts[std::size_t(t)] - e) * (counts[std::size_t(t)] - e) / e;
    ++cells;
  }
  if (pooled_exp >= 5) {
    chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++cells;
  } else if (pooled_obs > 0 && pooled_exp == 0) {
    return 0.0;  // a sample where the probability is 0
  }
  return chi2_survival(chi2, cells - 1);
}

TEST(EnvironmentDistribution, EnvironmentSamplerPassesChiSquare) {
  const std::vector<EnvMap> envs = {latlong_env(smooth_radiance(), 32), latlong_env(sunny_radiance(), 32, 8),
                                    latlong_env(patterns::latlong_checker(30.0, 0.0, 1.0), 32)};
  const double alpha = sidak(0.01, int(envs.size()));
  for (std::size_t i = 0; i < envs.size(); ++i) {
    const EnvironmentDistribution d(envs[i]);
    long mismatched = 0;
    const double p = texel_chi2_p_value(d, 400000, 17 + i, &mismatched);
    EXPECT_GT(p, alpha) << "environment " << i;
    // A sample may round into a neighbour only exactly on a cell boundary.
    EXPECT_LE(mismatched, 4) << "environment " << i;
  }
}

TEST(EnvironmentDistribution, PdfIsProbabilityOverSolidAngleAndSumsToOne) {
  const EnvMap env = latlong_env(sunny_radiance(), 32, 8);
  const EnvironmentDistribution d(env);
  double total = 0, integral = 0;
  for (long t = 0; t < env.layout.texel_count(); ++t) {
    total += d.probability(t);
    const int c = int(t % env.layout.width()), r = int(t / env.layout.width());
    const Vec3 dir = *env.layout.texel_direction(c, r);
    integral += d.pdf(dir) * env.layout.texel_solid_angle(c, r);
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_NEAR(integral, 1.0, 1e-9);
  integrator_detail::TexelRng rng(3, 0);
  for (int i = 0; i < 1000; ++i) {
    const auto s = d.sample(rng.uniform2());
    ASSERT_NEAR(s.dir.norm(), 1.0, 1e-12);
    EXPECT_DOUBLE_EQ(d.pdf(s.dir), s.pdf);
  }
}

TEST(EnvironmentDistribution, ZeroAndNegativeTexelsAreNeverSampledUnlessAllAreZero) {
  EnvMap env = EnvMap::zeros(Layout(LayoutKind::LatLong, 16, 8));
  env.pixels.at<cv::Vec3f>(3, 5) = cv::Vec3f(2, 2, 2);
  env.pixels.at<cv::Vec3f>(4, 5) = cv::Vec3f(-5, -5, -5);
  env.pixels.at<cv::Vec3f>(2, 2) = cv::Vec3f(std::nanf(""), 1, 1);
  const EnvironmentDistribution d(env);
  EXPECT_EQ(d.probability(4 * 16 + 5), 0.0);
  EXPECT_GT(d.probability(2 * 16 + 2), 0.0);
  integrator_detail::TexelRng rng(5, 0);
  for (int i = 0; i < 2000; ++i) {
    const long t = d.sample(rng.uniform2()).texel;
    EXPECT_TRUE(t == 3 * 16 + 5 || t == 2 * 16 + 2) << t;
  }
  const EnvironmentDistribution uniform(EnvMap::zeros(Layout(LayoutKind::LatLong, 16, 8)));
  EXPECT_NEAR(uniform.pdf(Vec3(0, 0, 1)), 1.0 / (4 * kPi), 1e-9);
}

}  // namespace
}  // namespace rsibr::test
