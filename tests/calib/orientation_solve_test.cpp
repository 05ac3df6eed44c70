// calib/orientation/orientation_solve.h: the cost's gradient, orientation accuracy with realistic noise and
// outliers, the reported uncertainty against the observed error, clear errors.
#include "calib/orientation/orientation_solve.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "random_directions.h"

#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <ceres/sphere_manifold.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace rsibr {
namespace {

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0, 1);
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

TEST(OrientationSolve, CostFunctionPassesTheGradientCheck) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 10; ++trial) {
    const Vec3 o = testing::random_direction(rng);
    auto* cost = new ceres::AutoDiffCostFunction<DirectionResidual, 3, 4, 3>(new DirectionResidual(o, 0.01));
    const ceres::EigenQuaternionManifold qm;
    const ceres::SphereManifold<3> sm;
    Eigen::Quaterniond q(random_rotation(rng));
    Vec3 d = testing::random_direction(rng);
    double* x[] = {q.coeffs().data(), d.data()};
    const ceres::Manifold* manifolds[] = {&qm, &sm};
    // The cost's (autodiff) Jacobian in each block's tangent space, J_ambient * PlusJacobian, against
    // central differences of the residual along the manifold, r(Plus(x, +h e_k)) - r(Plus(x, -h e_k)).
    // (Written out rather than with ceres::GradientChecker: its ProbeResults hold Eigen matrices that
    // the prebuilt libceres allocates with plain malloc, which an ASan build of this file would free
    // with Eigen's handmade aligned free: Eigen drops its malloc-is-aligned assumption under ASan.)
    double r0[3], J0[3 * 4], J1[3 * 3];
    double* J[] = {J0, J1};
    ASSERT_TRUE(cost->Evaluate(x, r0, J));
    const int ambient[] = {4, 3};
    for (int b = 0; b < 2; ++b) {
      const ceres::Manifold& m = *manifolds[b];
      const int n = ambient[b], t = m.TangentSize();
      std::vector<double> P(std::size_t(n * t));
      ASSERT_TRUE(m.PlusJacobian(x[b], P.data()));
      for (int k = 0; k < t; ++k) {
        const double h = 1e-6;
        double rp[3], rm[3];
        std::vector<double> delta(static_cast<std::size_t>(t), 0.0), xp(static_cast<std::size_t>(n)),
            xm(static_cast<std::size_t>(n));
        delta[std::size_t(k)] = h;
        ASSERT_TRUE(m.Plus(x[b], delta.data(), xp.data()));
        delta[std::size_t(k)] = -h;
        ASSERT_TRUE(m.Plus(x[b], delta.data(), xm.data()));
        double* xs[] = {x[0], x[1]};
        xs[b] = xp.data();
        ASSERT_TRUE(cost->Evaluate(xs, rp, nullptr));
        xs[b] = xm.data();
        ASSERT_TRUE(cost->Evaluate(xs, rm, nullptr));
        for (int i = 0; i < 3; ++i) {
          double analytic = 0;
          for (int a = 0; a < n; ++a) analytic += J[b][i * n + a] * P[std::size_t(a * t + k)];
          const double numeric = (rp[i] - rm[i]) / (2 * h);
          EXPECT_NEAR(analytic, numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
              << "block " << b << " (" << i << "," << k << ")";
        }
      }
    }
    delete cost;
  }
}

struct Case {
  int views = 8, features = 400;
  double sigma_deg = 0.2;  // per observed direction: ~0.15 px (SIFT) on a 100 px ball, doubled by the reflection
  double visible = 0.6;    // fraction of features each view sees
  double outliers = 0.05;  // mismatched observations (random directions)
};

struct Truth {
  std::vector<Mat3> world_from_cam;
  std::vector<Vec3> d;
  std::vector<DirectionObservation> obs;
};

Truth make_case(const Case& c, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Truth t;
  for (int v = 0; v < c.views; ++v) t.world_from_cam.push_back(v == 0 ? Mat3::Identity() : random_rotation(rng));
  for (int f = 0; f < c.features; ++f) t.d.push_back(testing::random_direction(rng));
  const double sigma = c.sigma_deg * kPi / 180;
  for (int v = 0; v < c.views; ++v)
    for (int f = 0; f < c.features; ++f) {
      if (u(rng) > c.visible) continue;
      Vec3 o = testing::perturb(t.world_from_cam[v].transpose() * t.d[f], sigma, rng);
      if (u(rng) < c.outliers) o = testing::random_direction(rng);
      t.obs.push_back({v, f, o, sigma});
    }
  return t;
}

double rotation_error_deg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / kPi;
}

// 0.2 degrees of noise per direction, 400 features (60% seen per view), 5% outliers: the median orientation error is at most 0.05
// degrees, and the reported std devs match the observed errors: the mean of (error / sigma)^2 over
// the views of several seeds is about 1 (a rotation error's three axes each contribute one sigma^2/3
// to the whole-rotation variance that sigma_deg reports, so E[error^2] = sigma_deg^2).
TEST(OrientationSolve, MedianErrorBelowFiveHundredthsOfADegreeAndUncertaintyConsistent) {
  const Case c;
  std::vector<double> errors;
  double chi2 = 0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Truth t = make_case(c, seed);
    const OrientationSolution s = solve_orientations(c.views, c.features, t.obs);
    EXPECT_EQ(s.sigma_deg[0], 0);
    for (int v = 1; v < c.views; ++v) {
      const double e = rotation_error_deg(s.world_from_cam[v], t.world_from_cam[v]);
      errors.push_back(e);
      ASSERT_TRUE(std::isfinite(s.sigma_deg[v]) && s.sigma_deg[v] > 0);
      chi2 += (e / s.sigma_deg[v]) * (e / s.sigma_deg[v]);
      ++n;
    }
  }
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  std::printf("  %d views: median orientation error %.4f deg, max %.4f deg, mean (error/sigma)^2 = %.3f\n", n, median,
              errors.back(), chi2 / n);
  EXPECT_LE(median, 0.05);
  // 42 samples of a chi-square(3)/3 variable: mean 1, std dev sqrt(2/3/42) ~ 0.13.
  EXPECT_GT(chi2 / n, 0.6);
  EXPECT_LT(chi2 / n, 1.5);
}

// Each feature's direction to about sigma / sqrt(views seeing it); features whose few observations
// are all mismatches (5% outliers) are lost, so the 95th percentile is checked, not the worst.
TEST(OrientationSolve, FeatureDirectionsAreRecovered) {
  const Truth t = make_case(Case{}, 9);
  const OrientationSolution s = solve_orientations(8, 400, t.obs);
  std::vector<double> err;
  for (int f = 0; f < 400; ++f)
    if (s.feature_directions[f].squaredNorm() > 0)
      err.push_back(std::acos(std::clamp(s.feature_directions[f].dot(t.d[f]), -1.0, 1.0)) * 180 / kPi);
  std::sort(err.begin(), err.end());
  EXPECT_LT(err[err.size() / 2], 0.2);
  EXPECT_LT(err[err.size() * 95 / 100], 1.0);
  EXPECT_NEAR(s.rms_sigmas, std::sqrt(2.0), 0.3);  // two tangent components of sigma each
}

TEST(OrientationSolve, TooFewViewsOrNoSharedFeaturesAreClearErrors) {
  const Truth t = make_case(Case{}, 3);
  EXPECT_THROW(solve_orientations(1, 400, t.obs), std::invalid_argument);
  // View 1 sees features 0..9, view 0 features 10..19: nothing ties them.
  std::vector<DirectionObservation> obs;
  for (int f = 0; f < 20; ++f) obs.push_back({f < 10 ? 1 : 0, f, Vec3(0, 0, 1), 0.01});
  try {
    solve_orientations(2, 20, obs);
    FAIL();
  } catch (const OrientationError& e) {  // the view as data, for the caller to name
    EXPECT_EQ(e.view(), 1);
    EXPECT_EQ(e.problem().rfind("shares 0 feature(s)", 0), 0u) << e.problem();
    EXPECT_EQ(std::string(e.what()), "orientation: view 1: " + e.problem());
  }
  try {
    solve_orientations(1, 400, t.obs);
    FAIL();
  } catch (const OrientationError& e) {  // concerns no view
    EXPECT_EQ(e.view(), -1);
    EXPECT_EQ(std::string(e.what()), "orientation: " + e.problem());
  }
}

// A view whose features no other view shares (a wrong ball in it, say) is left out when asked,
// with the reason, and the others are solved as before.
TEST(OrientationSolve, AViewSharingNothingIsLeftOutWhenAskedAndTheRestAreSolved) {
  Truth t = make_case(Case{}, 4);
  std::mt19937_64 rng(12);
  for (int f = 400; f < 450; ++f) t.obs.push_back({8, f, testing::random_direction(rng), 0.0035});
  EXPECT_THROW(solve_orientations(9, 450, t.obs), std::invalid_argument);
  OrientationOptions o;
  o.leave_out_unplaced = true;
  const OrientationSolution s = solve_orientations(9, 450, t.obs, o);
  ASSERT_EQ(s.oriented.size(), 9u);
  EXPECT_EQ(s.oriented[8], 0);
  EXPECT_NE(s.left_out[8].find("shares fewer than 3 features"), std::string::npos);
  for (int v = 1; v < 8; ++v) {
    EXPECT_EQ(s.oriented[v], 1);
    EXPECT_TRUE(s.left_out[v].empty());
    EXPECT_LT(rotation_error_deg(s.world_from_cam[v], t.world_from_cam[v]), 0.2) << v;
  }
}

// Known rotations (a pose file without balls): held exactly, and each view's ball refined by the
// features from a prior 1 degree off to within a few hundredths of a degree.
TEST(OrientationSolve, KnownRotationsAreHeldAndTheBallsRefinedFromThem) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g(0, 1);
  const int views = 4, features = 300;
  std::vector<Mat3> r;
  for (int v = 0; v < views; ++v) r.push_back(random_rotation(rng));
  std::vector<Vec3> axis(views);
  std::vector<double> sine(views, 0.1);  // the ball 10 radii away
  OrientationOptions o;
  o.fixed_world_from_cam = r;
  std::vector<DirectionObservation> obs;
  const double sigma = 0.05 * kPi / 180;
  for (int v = 0; v < views; ++v) {
    axis[v] = Vec3(0.1 * g(rng), 0.1 * g(rng), 1).normalized();
    const Vec3 prior = Eigen::AngleAxisd(kPi / 180, axis[v].unitOrthogonal()).toRotationMatrix() * axis[v];
    o.balls.push_back({prior, std::asin(sine[v]), kPi / 180, 0});
  }
  for (int f = 0; f < features; ++f) {
    const Vec3 d = testing::random_direction(rng);
    for (int v = 0; v < views; ++v) {
      // The camera ray that reflects into d, where d is not behind the ball (the rim).
      const Vec3 rc = r[v].transpose() * d, c = axis[v] / sine[v];
      if (rc.dot(axis[v]) > 0.3) continue;
      const auto n = reflection_normal(c, rc, (rc.normalized() - axis[v]).normalized());
      if (!n) continue;
      obs.push_back({v, f, rc, sigma, (c + *n).normalized(), -1});
    }
  }
  const OrientationSolution s = solve_orientations(views, features, obs, o);
  for (int v = 0; v < views; ++v) {
    EXPECT_LT(rotation_error_deg(s.world_from_cam[v], r[v]), 1e-9) << v;
    EXPECT_EQ(s.sigma_deg[v], 0);
    EXPECT_LT(angle_between(s.ball_axes[v], axis[v]) * 180 / kPi, 0.05) << v;
  }
}
}  // namespace
}  // namespace rsibr
