// Fresnel reflectance: closed forms at normal incidence, grazing, total internal reflection, and
// the conductor formula against the dielectric one.
#include "bake/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace rsibr {
namespace {

TEST(Fresnel, ConductorWithZeroKEqualsDielectric) {
  double worst = 0;
  for (double eta : {1.2, 1.5, 2.4, 1.0 / 1.5, 0.9}) {
    const ConductorFresnel conductor(Vec3::Constant(eta), Vec3::Zero());
    const DielectricFresnel dielectric(eta);
    for (int i = 0; i <= 1000; ++i) {
      const double c = i / 1000.0;
      const double d = std::abs(conductor.eval(c).x() - dielectric.eval(c).x());
      EXPECT_LT(d, 1e-12) << "eta " << eta << " cos " << c;
      worst = std::max(worst, d);
    }
  }
  std::printf("  max |conductor(k=0) - dielectric| = %.2e\n", worst);
}

TEST(Fresnel, SchlickAtNormalIncidenceEqualsF0) {
  const Vec3 f0(0.04, 0.5, 0.95);
  const SchlickFresnel f(f0);
  EXPECT_EQ(f.eval(1.0), f0);
  EXPECT_NEAR((f.eval(0.0) - Vec3::Ones()).norm(), 0.0, 1e-15);
  EXPECT_LT(f.eval(0.5).x(), f.eval(0.1).x());  // grows toward grazing
}

TEST(Fresnel, DielectricNormalIncidenceIsClosedForm) {
  for (double eta : {1.33, 1.5, 2.4}) {
    const double r0 = std::pow((eta - 1) / (eta + 1), 2.0);
    EXPECT_NEAR(fresnel_dielectric(1.0, eta), r0, 1e-15) << eta;
  }
}

TEST(Fresnel, DielectricReachesOneAtGrazing) {
  for (double eta : {1.01, 1.33, 1.5, 2.4}) {
    EXPECT_EQ(fresnel_dielectric(0.0, eta), 1.0) << eta;
    EXPECT_GT(fresnel_dielectric(1e-9, eta), 1.0 - 1e-7) << eta;
    // Monotone toward grazing.
    double prev = 0;
    for (int i = 1000; i >= 0; --i) {
      const double f = fresnel_dielectric(i / 1000.0, eta);
      EXPECT_GE(f, prev - 1e-15);
      prev = f;
    }
  }
}

TEST(Fresnel, DielectricTotalInternalReflection) {
  // Light inside glass (relative index 1/1.5): beyond the critical angle everything reflects.
  const double eta = 1.0 / 1.5;
  const double cos_critical = std::sqrt(1.0 - eta * eta);
  EXPECT_EQ(fresnel_dielectric(cos_critical * 0.999, eta), 1.0);
  EXPECT_EQ(fresnel_dielectric(0.0, eta), 1.0);
  EXPECT_LT(fresnel_dielectric(cos_critical * 1.01, eta), 1.0);
  EXPECT_GT(fresnel_dielectric(cos_critical * 1.0001, eta), 0.9);  // continuous at the critical angle
  EXPECT_NEAR(fresnel_dielectric(1.0, eta), 0.04, 1e-15);          // same R0 from either side
  // The complex formula agrees through TIR.
  EXPECT_NEAR(fresnel_complex(cos_critical * 0.5, {eta, 0.0}), 1.0, 1e-12);
}

TEST(Fresnel, ConductorNormalIncidenceIsClosedForm) {
  const Vec3 n(0.2, 0.9, 1.1), k(3.9, 2.4, 2.2);
  const ConductorFresnel f(n, k);
  for (int c = 0; c < 3; ++c) {
    const double r0 = ((n[c] - 1) * (n[c] - 1) + k[c] * k[c]) / ((n[c] + 1) * (n[c] + 1) + k[c] * k[c]);
    EXPECT_NEAR(f.eval(1.0)[c], r0, 1e-14);
    EXPECT_NEAR(f.eval(0.0)[c], 1.0, 1e-12);
  }
}

TEST(Fresnel, ReflectanceStaysInTheUnitInterval) {
  const std::shared_ptr<const Fresnel> all[] = {
      std::make_shared<NoFresnel>(), std::make_shared<SchlickFresnel>(Vec3(0, 0.5, 1)),
      std::make_shared<DielectricFresnel>(1.5), std::make_shared<DielectricFresnel>(0.5),
      std::make_shared<ConductorFresnel>(Vec3(0.2, 1.0, 3.0), Vec3(0.0, 2.0, 10.0))};
  for (const auto& f : all)
    for (double c : {-1.0, -0.3, 0.0, 1e-300, 1e-9, 0.3, 0.999999, 1.0, 1.5}) {
      const Vec3 v = f->eval(c);
      EXPECT_TRUE(v.allFinite()) << f->spec() << " " << c;
      EXPECT_GE(v.minCoeff(), 0.0) << f->spec() << " " << c;
      EXPECT_LE(v.maxCoeff(), 1.0) << f->spec() << " " << c;
    }
}

}  // namespace
}  // namespace rsibr

namespace rsibr {
namespace {

// The real-arithmetic conductor formula (what ConductorFresnel evaluates) equals the complex-amplitude
// definition, including k = 0 below and beyond the critical angle, grazing and normal incidence.
TEST(Fresnel, RealConductorFormulaEqualsComplexAmplitudes) {
  const double etas[] = {0.05, 0.2, 0.67, 1.0, 1.5, 3.0};
  const double ks[] = {0.0, 1e-6, 0.5, 2.45, 3.9, 10.0};
  double worst = 0;
  for (double eta : etas)
    for (double k : ks)
      for (int i = 0; i <= 2000; ++i) {
        const double c = i / 2000.0;
        const double ref = fresnel_complex(c, {eta, k});
        const double got = fresnel_conductor(c, eta, k);
        ASSERT_TRUE(std::isfinite(got));
        worst = std::max(worst, std::abs(got - ref));
      }
  EXPECT_LT(worst, 1e-11);  // both forms are good to a few 1e-13 against 40-digit arithmetic
  EXPECT_EQ(fresnel_conductor(0.0, 0.2, 3.9), 1.0);
}

}  // namespace
}  // namespace rsibr
