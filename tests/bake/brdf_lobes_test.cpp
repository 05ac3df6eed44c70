// Multi-lobe split (bake/brdf_lobes.h): the parts sum to the parent, each part's white furnace is
// its albedo and the albedos sum to the parent's, the parts' samplers keep the sampling contract,
// and a part's spec round-trips through make_brdf.
#include "bake/brdf_lobes.h"
#include "bake/brdf_spec.h"

#include "tests/bake/brdf_cases.h"
#include "tests/bake/chi2.h"
#include "tests/bake/integrator_cases.h"
#include "tests/bake/sphere_quadrature.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace rsibr::test {
namespace {

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

std::string error_of(const std::string& text) {
  try {
    parse_brdf(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

const std::string kPaint =
    "{type: clearcoat, coat: {ior: 1.5, roughness: 0.05}, flakes: {coverage: 0.3, roughness: 0.3, fresnel: {type: "
    "conductor, eta: [1.66, 0.88, 0.52], k: [9.22, 6.27, 4.84]}}, base: {albedo: [0.5, 0.05, 0.03]}}";

TEST(BrdfLobes, SplitFollowsTheBrdfsLobes) {
  const auto lambert = split_lobes(std::make_shared<LambertBrdf>(Vec3(0.5, 0.5, 0.5)));
  ASSERT_EQ(lambert.size(), 1u);
  EXPECT_EQ(lambert[0]->central_direction(), CentralDirection::Normal);
  const auto g = split_lobes(ggx(0.2));
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0]->central_direction(), CentralDirection::Mirror);
  const auto paint = split_lobes(car_paint());
  ASSERT_EQ(paint.size(), 2u);
  EXPECT_EQ(paint[0]->central_direction(), CentralDirection::Normal);
  EXPECT_EQ(paint[1]->central_direction(), CentralDirection::Mirror);
  // Full flake coverage or a black binder: no diffuse part.
  EXPECT_EQ(split_lobes(car_paint(0.05, 1.0)).size(), 1u);
  EXPECT_EQ(split_lobes(car_paint(0.05, 0.3, 0.3, Vec3::Zero())).size(), 1u);
  EXPECT_THROW(BrdfLobe(ggx(0.2), CentralDirection::Normal), std::invalid_argument);
  EXPECT_THROW(BrdfLobe(nullptr, CentralDirection::Normal), std::invalid_argument);
}

TEST(BrdfLobes, PartsSumToTheParentEval) {
  std::mt19937_64 rng(5);
  double worst = 0;
  for (const auto& c : sampler_cases()) {
    const auto parts = split_lobes(c.brdf);
    ASSERT_FALSE(parts.empty()) << c.name;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 wo = random_upper(rng);
      Vec3 wi = random_upper(rng);
      if (i % 3 == 0) wi = Vec3(-wo.x(), -wo.y(), wo.z());  // the mirror peak
      Vec3 sum = Vec3::Zero();
      for (const auto& p : parts) {
        const Vec3 e = p->eval(wo, wi);
        ASSERT_TRUE(e.allFinite() && e.minCoeff() >= 0.0) << c.name;
        sum += e;
      }
      const Vec3 whole = c.brdf->eval(wo, wi);
      const double rel = (sum - whole).cwiseAbs().maxCoeff() / std::max(1e-300, whole.cwiseAbs().maxCoeff());
      EXPECT_LT(rel, 1e-12) << c.name << " wo " << wo.transpose() << " wi " << wi.transpose();
      worst = std::max(worst, rel);
    }
    // Below the horizon every part is 0, as the parent.
    for (const auto& p : parts) EXPECT_TRUE(p->eval(dir(0.5), Vec3(0, 0.6, -0.8)).isZero()) << c.name;
  }
  std::printf("  max relative |sum of parts - eval| = %.2e\n", worst);
}

TEST(BrdfLobes, WhiteFurnaceOfEachPartIsItsAlbedoAndTheyAddUp) {
  struct Job {
    std::string name;
    std::shared_ptr<const Brdf> part;
    Vec3 wo, furnace, albedo;
  };
  std::vector<Job> jobs;
  std::vector<std::pair<std::string, std::shared_ptr<const Brdf>>> parents = {
      {"clearcoat", car_paint()},
      {"clearcoat_rough",
       car_paint(0.4, 0.7, 0.08, Vec3(0.9, 0.9, 0.9), std::make_shared<SchlickFresnel>(Vec3(0.95, 0.9, 0.8)))},
      {"paint", parse_brdf(kPaint)},
      {"lambert", std::make_shared<LambertBrdf>(Vec3(0.5, 0.6, 0.7))},
      {"ggx_a0.3", ggx(0.3)}};
  for (const auto& [name, brdf] : parents) {
    const auto parts = split_lobes(brdf);
    for (const Vec3& wo : test_wos()) {
      Vec3 sum = Vec3::Zero();
      for (const auto& p : parts) {
        sum += p->albedo(wo);
        jobs.push_back({name + "." + to_string(p->central_direction()), p, wo, {}, {}});
      }
      EXPECT_LT((sum - brdf->albedo(wo)).cwiseAbs().maxCoeff(), 1e-12) << name << " cos_o " << wo.z();
    }
  }
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    QuadratureOptions q;
    q.tol = 1e-7;
    j.furnace = integrate_sphere<Vec3>([&](const Vec3& wi) { return j.part->eval(j.wo, wi); },
                                       peak_breaks(lobe_peaks(j.wo)), 0.0, 1.0, q);
    j.albedo = j.part->albedo(j.wo);
  });
  double worst = 0;
  for (const Job& j : jobs) {
    const double err = (j.albedo - j.furnace).cwiseAbs().maxCoeff();
    EXPECT_LT(err, 1e-3) << j.name << " cos_o = " << j.wo.z() << ": albedo " << j.albedo.transpose() << " vs furnace "
                         << j.furnace.transpose();
    worst = std::max(worst, err);
  }
  std::printf("  max |part albedo() - part furnace integral| = %.2e over %zu parts x views\n", worst, jobs.size());
}

TEST(BrdfLobes, PartSampleWeightIsPartEvalOverParentPdf) {
  std::mt19937_64 rng(9);
  for (const auto& part : split_lobes(car_paint())) {
    const auto& lobe = static_cast<const BrdfLobe&>(*part);
    int valid = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 wo = random_upper(rng);
      const Vec2 u(canonical(rng), canonical(rng));
      const BrdfSample s = part->sample(wo, u), whole = lobe.parent().sample(wo, u);
      ASSERT_EQ(s.valid, whole.valid);
      EXPECT_EQ(s.wi, whole.wi);
      EXPECT_EQ(s.pdf, part->pdf(wo, s.wi));
      if (!s.valid) {
        EXPECT_TRUE(s.weight.isZero());
        continue;
      }
      ++valid;
      double p = 0;
      const Vec3 e = part->eval_pdf(wo, s.wi, &p);
      EXPECT_EQ(p, s.pdf);
      EXPECT_LT((s.weight - e / p).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, e.maxCoeff() / p));
    }
    EXPECT_GT(valid, 1000);
  }
}

TEST(BrdfLobes, PartSamplersMatchTheirPdfChiSquare) {
  const auto parts = split_lobes(car_paint());
  struct Job {
    std::string name;
    const Brdf* brdf;
    Vec3 wo;
    Chi2Result r;
  };
  std::vector<Job> jobs;
  for (const auto& p : parts)
    for (const Vec3& wo : {dir(0.7, 0.3), dir(0.2, 2.0)})
      jobs.push_back({to_string(p->central_direction()), p.get(), wo, {}});
  const double alpha = sidak(0.01, int(jobs.size()));
  std::uint64_t seed = 77;
  for (Job& j : jobs) {
    Chi2Options o;
    o.seed = seed++;
    o.breaks.z = {-j.wo.z(), 0.0, j.wo.z()};
    o.breaks.phi = {std::atan2(-j.wo.y(), -j.wo.x())};
    j.r = chi2_test(
        [&](const Vec2& u) -> std::optional<DirectionSample> {
          const BrdfSample s = j.brdf->sample(j.wo, u);
          if (s.wi.isZero()) return std::nullopt;
          return DirectionSample{s.wi, s.pdf};
        },
        [&](const Vec3& wi) { return j.brdf->pdf(j.wo, wi); }, o);
    EXPECT_TRUE(j.r.error.empty()) << j.name << " " << j.r.summary();
    EXPECT_GT(j.r.p_value, alpha) << j.name << " " << j.r.summary();
  }
}

TEST(BrdfLobes, PartWidthsAndDirections) {
  const auto paint = car_paint();
  const auto parts = split_lobes(paint);
  const Vec3 n(0, 0, 1);
  EXPECT_DOUBLE_EQ(parts[0]->lobe_width(n), LambertBrdf(Vec3::Constant(0.5)).lobe_width(n));
  EXPECT_DOUBLE_EQ(parts[1]->lobe_width(n), paint->lobe_width(n));  // the coat sets both
  EXPECT_LT(parts[1]->lobe_width(n), parts[0]->lobe_width(n));
  // A one-lobe BRDF's part is the BRDF.
  const auto g = ggx(0.3);
  EXPECT_DOUBLE_EQ(split_lobes(g)[0]->lobe_width(n), g->lobe_width(n));
}

TEST(BrdfLobes, PartMapsBakedWithOneSeedSumToTheWholeMap) {
  // A part samples with its parent's sampler and pdf, and every integrator is linear in eval for
  // fixed samples, so with one seed the parts' maps add up to the whole BRDF's map (to float
  // rounding): multi-lobe sets carry the whole BRDF's radiance, noise included. Exception: the
  // bright-texel quadrature (bake/bright_texels.h; mis, fis) picks its order from each part's own
  // lobe_width, so under a sun the parts are integrated at different orders (measured 4.8e-4).
  const std::shared_ptr<const Brdf> paint = car_paint();
  const auto parts = split_lobes(paint);
  const Vec3 view = Vec3(0.3, 0.4, 0.866).normalized();
  const Mat3 T = world_from_view_for(view);
  for (const auto& [env_name, env] :
       {std::pair{"smooth", latlong_env(smooth_radiance())}, std::pair{"sunny", latlong_env(sunny_radiance())}}) {
    for (const std::string method : {"mis", "fis", "reference"}) {
      const auto integrator = make_integrator(method, env);
      IntegratorOptions o;
      o.samples = 16;
      o.seed = 5;
      o.reference_width = 32;
      const cv::Mat whole = integrator->radiance_map(*paint, view, T, 16, o);
      cv::Mat sum =
          integrator->radiance_map(*parts[0], view, T, 16, o) + integrator->radiance_map(*parts[1], view, T, 16, o);
      const bool sun_quadrature = std::string(env_name) == "sunny" && method != "reference";
      EXPECT_LT(relative_rms(sum, whole), sun_quadrature ? 2e-3 : 1e-5) << env_name << " " << method;
    }
  }
}

TEST(BrdfLobes, LobeSpecRoundTrips) {
  for (const std::string& parent :
       {kPaint, std::string("{type: lambert, albedo: [0.2, 0.3, 0.4]}"),
        std::string("{type: ggx, roughness: 0.25, fresnel: {type: dielectric, ior: 1.5}}")}) {
    for (const auto& part : split_lobes(parse_brdf(parent))) {
      const std::string text = part->spec();
      EXPECT_TRUE(starts_with(
          text, std::string("{type: lobe, part: ") + to_string(part->central_direction()) + ", of: {type: "))
          << text;
      const auto back = parse_brdf(text);
      EXPECT_EQ(back->spec(), text);
      EXPECT_EQ(back->central_direction(), part->central_direction());
      std::mt19937_64 rng(3);
      for (int i = 0; i < 200; ++i) {
        const Vec3 wo = random_upper(rng), wi = random_upper(rng);
        EXPECT_EQ(back->eval(wo, wi), part->eval(wo, wi)) << text;
      }
    }
  }
}

TEST(BrdfLobes, LobeSpecParsingIsStrict) {
  EXPECT_TRUE(starts_with(error_of("{type: lobe, part: diffuse, of: " + kPaint + "}"),
                          "brdf.part: expected normal or mirror, got 'diffuse'"));
  EXPECT_TRUE(
      starts_with(error_of("{type: lobe, part: normal, of: " + kPaint + ", extra: 1}"), "brdf.extra: unknown key"));
  EXPECT_TRUE(starts_with(error_of("{type: lobe, part: normal}"), "brdf.of: missing"));
  EXPECT_TRUE(starts_with(error_of("{type: lobe, of: " + kPaint + "}"), "brdf.part: missing"));
  EXPECT_TRUE(
      starts_with(error_of("{type: lobe, part: normal, of: {type: ggx, roughness: 0.3, fresnel: {type: none}}}"),
                  "brdf.part: the BRDF in 'of' has no normal lobe"));
  EXPECT_TRUE(starts_with(error_of("{type: lobe, part: mirror, of: {type: lambert, albedo: [1, 1, 2]}}"),
                          "brdf.of.albedo[2]: must be in"));
}

}  // namespace
}  // namespace rsibr::test
