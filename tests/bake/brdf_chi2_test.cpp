// Every BRDF sampler against its own pdf: chi-square goodness of fit (tests/bake/chi2.h), and
// the harness itself against samplers that are known to be right and wrong.
#include "tests/bake/brdf_cases.h"
#include "tests/bake/chi2.h"

#include "bake/sample_warps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <vector>

namespace rsibr::test {
namespace {

constexpr double kFamilySignificance = 0.01;

Chi2Options options_for(const Vec3& wo, std::uint64_t seed) {
  Chi2Options o;
  o.seed = seed;
  // The visible-normal pdfs are discontinuous where the half vector crosses the horizon,
  // wi.z = -wo.z; the mirror-lobe peaks sit at the mirror direction.
  o.breaks.z = {-wo.z(), 0.0, wo.z()};
  o.breaks.phi = {std::atan2(-wo.y(), -wo.x())};
  return o;
}

TEST(Chi2Harness, AcceptsAnExactSampler) {
  // Uniform sphere sampling against 1/(4 pi).
  const auto r = chi2_test(
      [](const Vec2& u) -> std::optional<DirectionSample> {
        const double z = 1.0 - 2.0 * u.x(), phi = 2 * kPi * u.y(), s = std::sqrt(std::max(0.0, 1 - z * z));
        return DirectionSample{Vec3(s * std::cos(phi), s * std::sin(phi), z)};
      },
      [](const Vec3&) { return 1.0 / (4 * kPi); }, Chi2Options{});
  EXPECT_TRUE(r.error.empty()) << r.summary();
  EXPECT_GT(r.p_value, kFamilySignificance) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-9);
}

TEST(Chi2Harness, RejectsASlightlyWrongPdf) {
  // Samples from cos^1 but the pdf claims cos^1.1 (normalised): a 3% change of shape.
  const auto r = chi2_test(
      [](const Vec2& u) -> std::optional<DirectionSample> {
        return DirectionSample{warp::square_to_power_cosine(u, 1.0)};
      },
      [](const Vec3& w) { return warp::power_cosine_pdf(w.z(), 1.1); }, Chi2Options{});
  EXPECT_LT(r.p_value, 1e-6) << r.summary();
}

TEST(Chi2Harness, RejectsSamplesWherePdfIsZero) {
  const auto r = chi2_test(
      [](const Vec2& u) -> std::optional<DirectionSample> {
        Vec3 w = warp::square_to_cosine_hemisphere(u);
        if (u.x() < 0.01) w.z() = -w.z();  // 1% leak below the horizon
        return DirectionSample{w};
      },
      [](const Vec3& w) { return warp::cosine_hemisphere_pdf(w.z()); }, Chi2Options{});
  EXPECT_FALSE(r.error.empty()) << r.summary();
}

TEST(Chi2Harness, CountsFailedSamplesAgainstTheMissingMass) {
  // A sampler that drops 5% of its samples while its pdf still integrates to 1 must fail.
  const auto r = chi2_test(
      [](const Vec2& u) -> std::optional<DirectionSample> {
        if (u.y() < 0.05) return std::nullopt;
        return DirectionSample{warp::square_to_cosine_hemisphere(Vec2(u.x(), (u.y() - 0.05) / 0.95))};
      },
      [](const Vec3& w) { return warp::cosine_hemisphere_pdf(w.z()); }, Chi2Options{});
  EXPECT_LT(r.p_value, 1e-6) << r.summary();
}

TEST(BrdfSampling, EverySamplerMatchesItsPdfChiSquare) {
  const auto cases = sampler_cases();
  const auto wos = test_wos();
  struct Job {
    std::string name;
    const Brdf* brdf;
    Vec3 wo;
    std::uint64_t seed;
    Chi2Result result;
  };
  std::vector<Job> jobs;
  std::uint64_t seed = 1000;
  for (const auto& c : cases)
    for (const Vec3& wo : wos) jobs.push_back({c.name, c.brdf.get(), wo, seed++, {}});
  const double alpha = sidak(kFamilySignificance, int(jobs.size()));
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    j.result = chi2_test(
        [&](const Vec2& u) -> std::optional<DirectionSample> {
          const BrdfSample s = j.brdf->sample(j.wo, u);
          if (s.wi.isZero()) return std::nullopt;
          return DirectionSample{s.wi, s.pdf};
        },
        [&](const Vec3& wi) { return j.brdf->pdf(j.wo, wi); }, options_for(j.wo, j.seed));
  });
  double min_p = 1.0;
  std::string min_name;
  for (const Job& j : jobs) {
    SCOPED_TRACE(j.name + " cos_o = " + std::to_string(j.wo.z()));
    EXPECT_TRUE(j.result.error.empty()) << j.result.summary();
    EXPECT_GT(j.result.p_value, alpha) << j.result.summary();
    EXPECT_EQ(j.result.failed, 0) << j.result.summary();
    if (j.result.p_value < min_p) {
      min_p = j.result.p_value;
      min_name = j.name + " cos_o = " + std::to_string(j.wo.z());
    }
    std::printf("  chi2 %-16s cos_o=%-5.2f p=%.4f cells=%d pdf_integral=%.6f\n", j.name.c_str(), j.wo.z(),
                j.result.p_value, j.result.cells, j.result.pdf_integral);
  }
  std::printf("  %zu samplers x views, per-test significance %.2e (Sidak, family 0.01); min p = %.4f (%s)\n",
              jobs.size(), alpha, min_p, min_name.c_str());
}

}  // namespace
}  // namespace rsibr::test
