// Property tests of every BRDF: pdfs integrate to 1, white furnace = directional albedo,
// reciprocity, energy conservation, sample weights, finiteness at the extremes, lobe widths.
// Integrals come from an adaptive cubature over the sphere (tests/bake/sphere_quadrature.h)
// that shares nothing with the BRDFs' own samplers or albedo code.
#include "tests/bake/brdf_cases.h"
#include "tests/bake/sphere_quadrature.h"

#include "bake/sample_warps.h"
#include "bake/shading_frame.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace rsibr::test {
namespace {

// Integral of eval(wo, .) over the upper hemisphere (RGB).
Vec3 hemisphere_integral(const Brdf& b, const Vec3& wo, double tol = 1e-7) {
  QuadratureOptions q;
  q.tol = tol;
  return integrate_sphere<Vec3>([&](const Vec3& wi) { return b.eval(wo, wi); }, peak_breaks(lobe_peaks(wo)), 0.0, 1.0,
                                q);
}

// Integral of pdf(wo, .) over the sphere, with a break on the visible-normal cutoff z = -cos_o.
double pdf_integral(const Brdf& b, const Vec3& wo, double z0 = -1.0, double z1 = 1.0) {
  Breaks br = peak_breaks(lobe_peaks(wo));
  br.z.push_back(-wo.z());
  QuadratureOptions q;
  q.tol = 1e-6;
  return integrate_sphere<double>([&](const Vec3& wi) { return b.pdf(wo, wi); }, br, z0, z1, q);
}

TEST(BrdfPdf, PdfIntegratesToOne) {
  auto cases = sampler_cases();
  cases.push_back({"ggx_a0.01", ggx(0.01)});
  cases.push_back({"clearcoat_a0.01", car_paint(0.01)});
  struct Job {
    std::string name;
    const Brdf* brdf;
    Vec3 wo;
    double total = 0, upper = 0;
  };
  std::vector<Job> jobs;
  for (const auto& c : cases)
    for (const Vec3& wo : test_wos()) jobs.push_back({c.name, c.brdf.get(), wo});
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    j.upper = pdf_integral(*j.brdf, j.wo, 0.0, 1.0);
    j.total = j.upper + pdf_integral(*j.brdf, j.wo, -1.0, 0.0);
  });
  double worst = 0;
  for (const Job& j : jobs) {
    EXPECT_NEAR(j.total, 1.0, 1e-3) << j.name << " cos_o = " << j.wo.z() << " (upper hemisphere " << j.upper << ")";
    worst = std::max(worst, std::abs(j.total - 1.0));
  }
  std::printf("  max |integral of pdf - 1| over %zu cases: %.2e\n", jobs.size(), worst);
}

TEST(BrdfPdf, PdfIsZeroForViewsBelowTheHorizon) {
  for (const auto& c : sampler_cases()) {
    EXPECT_EQ(c.brdf->pdf(dir(-0.5), dir(0.5)), 0.0) << c.name;
    const BrdfSample s = c.brdf->sample(dir(-0.5), Vec2(0.3, 0.7));
    EXPECT_FALSE(s.valid) << c.name;
    EXPECT_TRUE(s.weight.isZero()) << c.name;
  }
}

TEST(WhiteFurnace, WhiteFurnaceGivesDirectionalAlbedoLambert) {
  const Vec3 rho(0.18, 0.5, 0.93);
  const LambertBrdf b(rho);
  for (double c : {1.0, 0.5, 0.01}) {
    const Vec3 wo = dir(c);
    EXPECT_EQ(b.albedo(wo), rho);  // exactly
    const Vec3 furnace = hemisphere_integral(b, wo);
    EXPECT_LT((furnace - rho).cwiseAbs().maxCoeff(), 1e-6) << furnace.transpose();
  }
}

TEST(WhiteFurnace, WhiteFurnaceGivesDirectionalAlbedoGgx) {
  // F = 1: the albedo is the single-scattering energy, never above 1; albedo() (visible-normal
  // quadrature) must agree with the independent hemisphere integral of eval to 1e-3.
  const std::vector<double> alphas = {0.01, 0.05, 0.1, 0.2, 0.5, 1.0};
  const std::vector<double> cosines = {1.0, 0.8, 0.5, 0.2, 0.05, 0.01};
  struct Job {
    double alpha, cos_o;
    double furnace = 0, albedo = 0;
  };
  std::vector<Job> jobs;
  for (double a : alphas)
    for (double c : cosines) jobs.push_back({a, c});
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    const GgxBrdf b(j.alpha, std::make_shared<NoFresnel>());
    const Vec3 wo = dir(j.cos_o, 0.7);
    j.furnace = hemisphere_integral(b, wo).x();
    j.albedo = b.albedo(wo).x();
  });
  double worst = 0, max_albedo = 0;
  for (const Job& j : jobs) {
    SCOPED_TRACE("alpha = " + std::to_string(j.alpha) + ", cos_o = " + std::to_string(j.cos_o));
    EXPECT_LE(j.furnace, 1.0 + 1e-6);
    EXPECT_LE(j.albedo, 1.0 + 1e-9);
    EXPECT_NEAR(j.albedo, j.furnace, 1e-3);
    worst = std::max(worst, std::abs(j.albedo - j.furnace));
    max_albedo = std::max(max_albedo, j.furnace);
  }
  std::printf("  GGX F=1: max |albedo() - furnace integral| = %.2e, max furnace albedo = %.6f\n", worst, max_albedo);
}

TEST(WhiteFurnace, AlbedoMatchesHemisphereIntegralForEveryBrdf) {
  auto cases = sampler_cases();
  struct Job {
    std::string name;
    const Brdf* brdf;
    Vec3 wo;
    Vec3 furnace, albedo;
  };
  std::vector<Job> jobs;
  for (const auto& c : cases)
    for (const Vec3& wo : test_wos()) jobs.push_back({c.name, c.brdf.get(), wo, {}, {}});
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    j.furnace = hemisphere_integral(*j.brdf, j.wo);
    j.albedo = j.brdf->albedo(j.wo);
  });
  double worst = 0;
  std::string worst_name;
  for (const Job& j : jobs) {
    const double err = (j.albedo - j.furnace).cwiseAbs().maxCoeff();
    EXPECT_LT(err, 1e-3) << j.name << " cos_o = " << j.wo.z() << ": albedo " << j.albedo.transpose() << " vs integral "
                         << j.furnace.transpose();
    if (err > worst) {
      worst = err;
      worst_name = j.name + " cos_o = " + std::to_string(j.wo.z());
    }
  }
  std::printf("  every BRDF: max |albedo() - furnace integral| = %.2e (%s)\n", worst, worst_name.c_str());
}

TEST(EnergyConservation, EnergyNeverExceedsOne) {
  // The brightest settings of every model: white reflectances, F = 1 or F0 = 1. (Phong below
  // e = 1 is left out only because cos^e with e < 1 has an infinite slope at the lobe's edge,
  // which the cubature resolves too slowly for a unit test.)
  const auto none = std::make_shared<NoFresnel>();
  std::vector<BrdfCase> cases = {
      {"lambert_white", std::make_shared<LambertBrdf>(Vec3::Ones())},
      {"phong_e1", std::make_shared<PhongBrdf>(Vec3::Ones(), 1.0)},
      {"phong_e100", std::make_shared<PhongBrdf>(Vec3::Ones(), 100.0)},
      {"blinn_e0.2", std::make_shared<BlinnPhongBrdf>(Vec3::Ones(), 0.2)},
      {"blinn_e1", std::make_shared<BlinnPhongBrdf>(Vec3::Ones(), 1.0)},
      {"blinn_e100", std::make_shared<BlinnPhongBrdf>(Vec3::Ones(), 100.0)},
      {"ggx_a0.05_F1", ggx(0.05, none)},
      {"ggx_a0.5_F1", ggx(0.5, none)},
      {"ggx_a1_F1", ggx(1.0, none)},
  };
  for (double coat_a : {0.02, 0.3, 1.0})
    for (double coverage : {0.0, 0.5, 1.0})
      cases.push_back({"clearcoat_a" + std::to_string(coat_a) + "_c" + std::to_string(coverage),
                       car_paint(coat_a, coverage, 0.2, Vec3::Ones(), none)});
  const std::vector<double> cosines = {1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.03, 0.01, 0.001};
  struct Job {
    std::string name;
    const Brdf* brdf;
    double cos_o;
    Vec3 furnace;
  };
  std::vector<Job> jobs;
  for (const auto& c : cases)
    for (double co : cosines) jobs.push_back({c.name, c.brdf.get(), co, {}});
  tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t k) {
    Job& j = jobs[k];
    j.furnace = hemisphere_integral(*j.brdf, dir(j.cos_o, 1.1), 1e-6);
  });
  double max_e = 0;
  std::string max_name;
  for (const Job& j : jobs) {
    EXPECT_LE(j.furnace.maxCoeff(), 1.0 + 1e-5) << j.name << " cos_o = " << j.cos_o;
    if (j.furnace.maxCoeff() > max_e) {
      max_e = j.furnace.maxCoeff();
      max_name = j.name + " cos_o = " + std::to_string(j.cos_o);
    }
  }
  std::printf("  max directional albedo over %zu bright cases: %.6f (%s)\n", jobs.size(), max_e, max_name.c_str());
}

// All BRDFs, including the extremes of roughness and exponent.
std::vector<BrdfCase> all_cases() {
  auto cases = sampler_cases();
  const auto none = std::make_shared<NoFresnel>();
  cases.push_back({"ggx_a0.001_gold", ggx(1e-3)});
  cases.push_back({"ggx_a0.001_schlick", ggx(1e-3, std::make_shared<SchlickFresnel>(Vec3(0.04, 0.5, 1.0)))});
  cases.push_back({"ggx_a1_dielectric", ggx(1.0, std::make_shared<DielectricFresnel>(1.5))});
  cases.push_back({"ggx_a1_none", ggx(1.0, none)});
  cases.push_back({"phong_e1e5", std::make_shared<PhongBrdf>(Vec3::Ones(), 1e5)});
  cases.push_back({"blinn_e1e5", std::make_shared<BlinnPhongBrdf>(Vec3::Ones(), 1e5)});
  cases.push_back({"clearcoat_a0.001", car_paint(1e-3, 0.5, 1e-3)});
  cases.push_back({"clearcoat_a1", car_paint(1.0, 0.5, 1.0)});
  return cases;
}

TEST(BrdfSymmetry, Reciprocity) {
  std::mt19937_64 rng(7);
  double worst = 0;
  for (const auto& c : all_cases()) {
    for (int i = 0; i < 2000; ++i) {
      const Vec3 wo = random_upper(rng), wi = random_upper(rng);
      const Vec3 a = c.brdf->eval(wo, wi) / wi.z(), b = c.brdf->eval(wi, wo) / wo.z();
      const double scale = std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
      // Relative, except among subnormal values (cos^1000 of a wide angle), which carry no digits.
      const double rel = scale > 1e-250 ? (a - b).cwiseAbs().maxCoeff() / scale : 0.0;
      ASSERT_LT(rel, 1e-10) << c.name << " wo = " << wo.transpose() << " wi = " << wi.transpose();
      worst = std::max(worst, rel);
    }
    // Exactly mirrored pairs (the peak of every mirror lobe).
    const Vec3 wo = dir(0.6, 0.4), wi = shading::reflect(wo, Vec3(0, 0, 1));
    EXPECT_NEAR((c.brdf->eval(wo, wi) / wi.z() - c.brdf->eval(wi, wo) / wo.z()).norm(), 0.0,
                1e-10 * (1 + c.brdf->eval(wo, wi).norm() / wi.z()))
        << c.name;
  }
  std::printf("  max relative reciprocity error: %.2e\n", worst);
}

TEST(BrdfSampling, SampleWeightEqualsEvalOverPdf) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double worst = 0;
  for (const auto& c : all_cases()) {
    int valid = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 wo = i % 4 == 0 ? dir(std::pow(uni(rng), 4.0), 6.28 * uni(rng)) : random_upper(rng);
      const BrdfSample s = c.brdf->sample(wo, Vec2(uni(rng), uni(rng)));
      ASSERT_TRUE(s.wi.allFinite() && s.weight.allFinite() && std::isfinite(s.pdf)) << c.name;
      if (!s.valid) {
        EXPECT_TRUE(s.weight.isZero()) << c.name;
        continue;
      }
      ++valid;
      EXPECT_NEAR(s.wi.norm(), 1.0, 1e-12) << c.name;
      EXPECT_GT(s.wi.z(), 0.0) << c.name;
      const double p = c.brdf->pdf(wo, s.wi);
      ASSERT_GT(p, 0.0) << c.name;
      EXPECT_NEAR(s.pdf / p, 1.0, 1e-9) << c.name;
      const Vec3 expect = c.brdf->eval(wo, s.wi) / p;
      const double scale = std::max(1e-300, expect.cwiseAbs().maxCoeff());
      const double rel = (s.weight - expect).cwiseAbs().maxCoeff() / scale;
      EXPECT_LT(rel, 1e-8) << c.name << " wo = " << wo.transpose() << " weight " << s.weight.transpose() << " vs "
                           << expect.transpose();
      worst = std::max(worst, rel);
    }
    EXPECT_GT(valid, 1000) << c.name;
  }
  std::printf("  max relative |weight - eval/pdf|: %.2e\n", worst);
}

TEST(BrdfExtremes, NoNaNAtGrazingAndNormalIncidence) {
  const Vec3 n(0, 0, 1);
  std::vector<Vec3> dirs = {n,
                            dir(1e-7, 0.0),
                            dir(1e-7, 2.0),
                            dir(1e-7, -kPi),
                            dir(0.7071, 1.0),
                            dir(0.0, 0.5),
                            dir(-1e-7, 0.3),
                            dir(-0.5, 1.0),
                            -n,
                            Vec3(1, 0, 0),
                            dir(0.999999999, 0.2)};
  const double below1 = std::nextafter(1.0, 0.0);
  const std::vector<Vec2> us = {Vec2(0, 0),      Vec2(below1, below1), Vec2(0.5, 0.5),    Vec2(0, below1),
                                Vec2(below1, 0), Vec2(0.25, 0.0),      Vec2(1e-300, 0.75)};
  for (const auto& c : all_cases()) {
    for (const Vec3& wo : dirs) {
      std::vector<Vec3> wis = dirs;
      wis.push_back(wo);
      wis.push_back(-wo);
      wis.push_back(shading::reflect(wo, n));
      for (const Vec3& wi : wis) {
        const Vec3 e = c.brdf->eval(wo, wi);
        const double p = c.brdf->pdf(wo, wi);
        ASSERT_TRUE(e.allFinite() && e.minCoeff() >= 0)
            << c.name << " wo " << wo.transpose() << " wi " << wi.transpose();
        ASSERT_TRUE(std::isfinite(p) && p >= 0) << c.name << " wo " << wo.transpose() << " wi " << wi.transpose();
        if (!(wo.z() > 0) || !(wi.z() > 0)) {
          EXPECT_TRUE(e.isZero()) << c.name << " below the horizon";
        }
      }
      for (const Vec2& u : us) {
        const BrdfSample s = c.brdf->sample(wo, u);
        ASSERT_TRUE(s.wi.allFinite() && s.weight.allFinite() && std::isfinite(s.pdf) && s.pdf >= 0 &&
                    s.weight.minCoeff() >= 0)
            << c.name << " wo " << wo.transpose() << " u " << u.transpose();
        if (s.valid) {
          EXPECT_GT(s.wi.z(), 0.0);
        }
      }
      const Vec3 a = c.brdf->albedo(wo);
      ASSERT_TRUE(a.allFinite() && a.minCoeff() >= 0 && a.maxCoeff() <= 1.0 + 1e-9)
          << c.name << " wo " << wo.transpose() << " albedo " << a.transpose();
      ASSERT_TRUE(std::isfinite(c.brdf->lobe_width(wo)) && c.brdf->lobe_width(wo) > 0) << c.name;
    }
  }
}

TEST(LobeWidth, LobeWidthHoldsTheEnergyFractionWhereExact) {
  // Lambert (every wo) and Phong (normal incidence): the cone of half-angle lobe_width about the
  // central direction holds 90% of the directional albedo.
  const auto fraction = [](const Brdf& b, const Vec3& wo, const Vec3& axis) {
    const double w = b.lobe_width(wo);
    QuadratureOptions q;
    q.tol = 1e-8;
    Breaks br = peak_breaks(lobe_peaks(wo));
    br.z.push_back(std::cos(w));  // the cone's edge (axis = n)
    const double inside = integrate_sphere<double>(
        [&](const Vec3& wi) { return axis.dot(wi) >= std::cos(w) ? b.eval(wo, wi).x() : 0.0; }, br, 0.0, 1.0, q);
    return inside / hemisphere_integral(b, wo).x();
  };
  const LambertBrdf lambert(Vec3::Constant(0.5));
  EXPECT_NEAR(fraction(lambert, dir(1.0), Vec3(0, 0, 1)), kLobeEnergyFraction, 1e-4);
  EXPECT_NEAR(fraction(lambert, dir(0.3), Vec3(0, 0, 1)), kLobeEnergyFraction, 1e-4);
  for (double e : {2.0, 50.0}) {
    const PhongBrdf phong(Vec3::Constant(0.5), e);
    EXPECT_NEAR(fraction(phong, dir(1.0), Vec3(0, 0, 1)), kLobeEnergyFraction, 1e-4) << e;
  }
  // GGX's closed form ignores G and the cosine: it is a measure, within a few percent.
  for (double a : {0.05, 0.2}) {
    const GgxBrdf g(a, std::make_shared<NoFresnel>());
    const double f = fraction(g, dir(1.0), Vec3(0, 0, 1));
    EXPECT_GT(f, 0.85) << a;
    EXPECT_LT(f, 0.95) << a;
    std::printf("  GGX alpha %.2f: lobe_width %.4f rad holds %.4f of the energy at normal incidence\n", a,
                g.lobe_width(dir(1.0)), f);
  }
}

TEST(LobeWidth, LobeWidthGrowsWithRoughness) {
  const auto none = std::make_shared<NoFresnel>();
  double prev = 0;
  for (double a : {0.001, 0.01, 0.05, 0.2, 0.5, 1.0}) {
    const double w = GgxBrdf(a, none).lobe_width(dir(1.0));
    EXPECT_GT(w, prev);
    prev = w;
  }
  prev = 10;
  for (double e : {1.0, 10.0, 100.0, 1e4}) {
    const double w = PhongBrdf(Vec3::Ones(), e).lobe_width(dir(1.0));
    const double wb = BlinnPhongBrdf(Vec3::Ones(), e).lobe_width(dir(1.0));
    EXPECT_LT(w, prev);
    EXPECT_GT(wb, 0.0);
    prev = w;
  }
  EXPECT_EQ(LambertBrdf(Vec3::Ones()).central_direction(), CentralDirection::Normal);
  EXPECT_EQ(GgxBrdf(0.1, none).central_direction(), CentralDirection::Mirror);
  // The clear coat's width is its sharpest significant lobe: the coat.
  EXPECT_NEAR(car_paint(0.05)->lobe_width(dir(0.7)), ggx_lobe_width(0.05), 1e-15);
}

}  // namespace
}  // namespace rsibr::test
