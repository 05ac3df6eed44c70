// lights/grey_source_cost.h: the written-out Jacobian against automatic differentiation of the
// model it states, the robust residual's squared norm against Ceres' Huber loss, the Jacobian of
// the robust residual against central differences, and the compressed block against the rows.
#include "lights/grey_source_cost.h"

#include "lights/light_source.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace rsibr {
namespace {

// The model of the header, for Ceres' automatic differentiation (one texel, no loss).
struct ReferenceCost {
  const GreyObservation* t;
  const std::vector<SourceFrame>* frames;
  template <typename T>
  bool operator()(T const* const* x, T* r) const {
    T m[3] = {T(t->known[0]), T(t->known[1]), T(t->known[2])};
    for (std::size_t s = 0; s < frames->size(); ++s) {
      T d[3];
      source_direction((*frames)[s], x[s], d);
      const T c = T(t->n[0]) * d[0] + T(t->n[1]) * d[1] + T(t->n[2]) * d[2];
      const T k = light_kernels::mean_clamped_cosine(c, x[s][5]);
      for (int ch = 0; ch < 3; ++ch) m[ch] += x[s][2 + ch] * T(t->gain[ch]) * k;
    }
    for (int ch = 0; ch < 3; ++ch) r[ch] = T(t->sqrt_w * t->inv_scale[ch]) * (T(t->obs[ch]) - m[ch]);
    return true;
  }
};

struct Problem {
  std::vector<SourceFrame> frames;
  std::vector<std::array<double, kSourceBlock>> x;
  std::vector<GreyObservation> texels;
  std::vector<const double*> params() const {
    std::vector<const double*> p;
    for (const auto& b : x) p.push_back(b.data());
    return p;
  }
};

Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// Two sources: a disc (radius 0.3 rad, so many texels see it cross their horizon) and a point; the
// texels' normals all over the sphere, their observations scattered about the model so that some
// residuals are beyond a Huber scale (the median residual) and some within.
Problem make_problem(int texels, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2), p(0.5, 3.0), o(0.0, 2.0);
  Problem pr;
  for (int s = 0; s < 2; ++s) {
    SourceFrame f;
    f.d0 = random_unit(rng);
    f.t1 = f.d0.unitOrthogonal();
    f.t2 = f.d0.cross(f.t1);
    f.bound = 0.5;
    f.max_radius = 0.5;
    pr.frames.push_back(f);
    pr.x.push_back({u(rng), u(rng), p(rng), p(rng), p(rng), s == 0 ? 0.3 : 0.0});
  }
  for (int i = 0; i < texels; ++i) {
    GreyObservation t;
    t.n = random_unit(rng);
    t.obs = Vec3(o(rng), o(rng), o(rng));
    t.known = Vec3(0.1, 0.2, 0.15) * o(rng);
    t.gain = Vec3(0.18, 0.2, 0.16) / kPi;
    t.inv_scale = Vec3(1 / (0.1 + t.obs[0]), 1 / (0.1 + t.obs[1]), 1 / (0.1 + t.obs[2]));
    t.sqrt_w = 0.5 + 0.5 * o(rng);
    if (i % 3 == 0) t.stride = 2, t.sqrt_w *= 2;  // a sub-grid texel standing for 4
    pr.texels.push_back(t);
  }
  return pr;
}

// Every texel's rows (grey_texel_residuals): 3 N residuals and the (3 N) x P Jacobian, row-major.
struct Evaluated {
  std::vector<double> r;
  std::vector<double> J;
  int P = 0;
  double jac(std::size_t row, int source, int k) const { return J[row * std::size_t(P) + std::size_t(6 * source + k)]; }
};

Evaluated evaluate(const Problem& pr, double delta);

// A Huber scale with half the texels beyond it: the median residual norm.
double median_norm(const Problem& pr) {
  const Evaluated e = evaluate(pr, 0);
  std::vector<double> n;
  for (std::size_t i = 0; i < pr.texels.size(); ++i)
    n.push_back(std::sqrt(e.r[3 * i] * e.r[3 * i] + e.r[3 * i + 1] * e.r[3 * i + 1] + e.r[3 * i + 2] * e.r[3 * i + 2]));
  std::nth_element(n.begin(), n.begin() + long(n.size() / 2), n.end());
  return n[n.size() / 2];
}

Evaluated evaluate(const Problem& pr, double delta) {
  Evaluated e;
  e.P = kSourceBlock * int(pr.x.size());
  e.r.resize(3 * pr.texels.size());
  e.J.resize(e.r.size() * std::size_t(e.P));
  for (std::size_t i = 0; i < pr.texels.size(); ++i)
    grey_texel_residuals(pr.texels[i], pr.frames, pr.params().data(), delta, &e.r[3 * i],
                         &e.J[3 * i * std::size_t(e.P)]);
  return e;
}

// The compressed block's residuals and Jacobian, (P + 1) x P.
struct Compressed {
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
};

Compressed compressed(const Problem& pr, double delta) {
  std::vector<const GreyObservation*> ptrs;
  for (const auto& t : pr.texels) ptrs.push_back(&t);
  const GreySourceCost cost(ptrs, &pr.frames, delta);
  const int P = kSourceBlock * int(pr.x.size());
  EXPECT_EQ(cost.num_residuals(), P + 1);
  std::vector<std::vector<double>> blocks(pr.x.size(), std::vector<double>(std::size_t((P + 1) * kSourceBlock)));
  std::vector<double*> jac;
  for (auto& b : blocks) jac.push_back(b.data());
  Compressed c{Eigen::VectorXd(P + 1), Eigen::MatrixXd(P + 1, P)};
  EXPECT_TRUE(cost.Evaluate(pr.params().data(), c.r.data(), jac.data()));
  for (int row = 0; row <= P; ++row)
    for (std::size_t s = 0; s < pr.x.size(); ++s)
      for (int k = 0; k < kSourceBlock; ++k)
        c.J(row, kSourceBlock * int(s) + k) = blocks[s][std::size_t(row * kSourceBlock + k)];
  return c;
}

TEST(GreySourceCost, JacobianEqualsAutomaticDifferentiationOfTheModel) {
  const Problem pr = make_problem(400, 3);
  const Evaluated e = evaluate(pr, 0);
  int crossing = 0;
  for (std::size_t i = 0; i < pr.texels.size(); ++i) {
    ceres::DynamicAutoDiffCostFunction<ReferenceCost, kSourceBlock> ref(new ReferenceCost{&pr.texels[i], &pr.frames});
    for (std::size_t s = 0; s < pr.x.size(); ++s) ref.AddParameterBlock(kSourceBlock);
    ref.SetNumResiduals(3);
    double r[3];
    std::vector<std::array<double, 3 * kSourceBlock>> J(pr.x.size());
    std::vector<double*> jac;
    for (auto& j : J) jac.push_back(j.data());
    ASSERT_TRUE(ref.Evaluate(pr.params().data(), r, jac.data()));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e.r[3 * i + std::size_t(c)], r[c], 1e-12 * (1 + std::abs(r[c])));
    for (std::size_t s = 0; s < pr.x.size(); ++s)
      for (int k = 0; k < 3 * kSourceBlock; ++k) {
        const double want = J[s][std::size_t(k)],
                     got = e.jac(3 * i + std::size_t(k / kSourceBlock), int(s), k % kSourceBlock);
        ASSERT_NEAR(got, want, 1e-10 * (1 + std::abs(want))) << "texel " << i << " source " << s << " entry " << k;
      }
    // Texels whose normal is within the disc's radius of its horizon: the kernel's quadrature branch.
    const double c = pr.texels[i].n.dot(source_direction(pr.frames[0], pr.x[0].data()));
    crossing += std::abs(std::asin(std::clamp(c, -1.0, 1.0))) < 0.3;
  }
  EXPECT_GT(crossing, 20);  // the case that matters was exercised
}

TEST(GreySourceCost, SquaredResidualOfEachTexelIsItsHuberCost) {
  const Problem pr = make_problem(300, 5);
  const double delta = median_norm(pr);
  const Evaluated plain = evaluate(pr, 0), robust = evaluate(pr, delta);
  int beyond = 0;
  for (std::size_t i = 0; i < pr.texels.size(); ++i) {
    double sq = 0, robust_sq = 0;
    for (int c = 0; c < 3; ++c) {
      sq += plain.r[3 * i + std::size_t(c)] * plain.r[3 * i + std::size_t(c)];
      robust_sq += robust.r[3 * i + std::size_t(c)] * robust.r[3 * i + std::size_t(c)];
    }
    // A sub-grid texel's scale is delta * stride: its loss is stride^2 that of one map texel.
    const ceres::HuberLoss huber(delta * pr.texels[i].stride);
    double rho[3];
    huber.Evaluate(sq, rho);
    EXPECT_NEAR(robust_sq, rho[0], 1e-12 * (1 + rho[0]));
    beyond += sq > delta * delta;
  }
  EXPECT_GT(beyond, 100);
  EXPECT_LT(beyond, 200);  // both sides of the scale
}

TEST(GreySourceCost, RobustJacobianEqualsCentralDifferences) {
  Problem pr = make_problem(200, 9);
  const double delta = median_norm(pr);
  const Evaluated e = evaluate(pr, delta);
  const double h = 1e-6;
  for (std::size_t s = 0; s < pr.x.size(); ++s)
    for (int k = 0; k < kSourceBlock; ++k) {
      if (s == 1 && k == 5) continue;  // a point source: rho = 0 sits on the kernel's lower branch
      const double keep = pr.x[s][std::size_t(k)];
      pr.x[s][std::size_t(k)] = keep + h;
      const Evaluated up = evaluate(pr, delta);
      pr.x[s][std::size_t(k)] = keep - h;
      const Evaluated down = evaluate(pr, delta);
      pr.x[s][std::size_t(k)] = keep;
      for (std::size_t row = 0; row < e.r.size(); ++row) {
        const double numeric = (up.r[row] - down.r[row]) / (2 * h);
        const double got = e.jac(row, int(s), k);
        ASSERT_NEAR(got, numeric, 1e-5 * (1 + std::abs(numeric))) << "source " << s << " param " << k << " row " << row;
      }
    }
}

TEST(GreySourceCost, ResidualsAreFiniteAtThePoleOfTheDirectionsFrame) {
  // A texel whose normal is the source's direction exactly (cos theta = 1, the kernel's clamp) and
  // one exactly opposite: finite residuals and Jacobians.
  Problem pr = make_problem(2, 1);
  pr.x[0] = {0, 0, 1, 1, 1, 0.3};
  pr.texels[0].n = pr.frames[0].d0;
  pr.texels[1].n = -pr.frames[0].d0;
  const Evaluated e = evaluate(pr, 0.5);
  for (double r : e.r) EXPECT_TRUE(std::isfinite(r));
  for (double j : e.J) EXPECT_TRUE(std::isfinite(j));
  const Compressed c = compressed(pr, 0.5);
  EXPECT_TRUE(c.r.allFinite());
  EXPECT_TRUE(c.J.allFinite());
}

// The compressed block gives Ceres the same cost, gradient and Gauss-Newton matrix as the 3 N rows.
TEST(GreySourceCost, CompressedBlockHasTheRowsCostGradientAndNormalMatrix) {
  const Problem pr = make_problem(1000, 11);  // several chunks of texels
  const double delta = median_norm(pr);
  const Evaluated e = evaluate(pr, delta);
  const Compressed c = compressed(pr, delta);
  const Eigen::Map<const Eigen::VectorXd> r(e.r.data(), long(e.r.size()));
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
      e.J.data(), long(e.r.size()), e.P);
  EXPECT_NEAR(c.r.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
  const Eigen::VectorXd g = J.transpose() * r, gc = c.J.transpose() * c.r;
  EXPECT_LT((gc - g).norm(), 1e-9 * g.norm());
  const Eigen::MatrixXd A = J.transpose() * J, Ac = c.J.transpose() * c.J;
  EXPECT_LT((Ac - A).norm(), 1e-10 * A.norm());
  EXPECT_EQ(c.J.row(e.P).norm(), 0.0);
  // Without Jacobians, the cost alone.
  std::vector<const GreyObservation*> ptrs;
  for (const auto& t : pr.texels) ptrs.push_back(&t);
  const GreySourceCost cost(ptrs, &pr.frames, delta);
  Eigen::VectorXd only(e.P + 1);
  ASSERT_TRUE(cost.Evaluate(pr.params().data(), only.data(), nullptr));
  EXPECT_NEAR(only.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
}

// A source of zero power: its direction is invisible (zero columns), and the block still gives the
// cost and gradient, with no NaN.
TEST(GreySourceCost, ASourceWithoutPowerLeavesItsDirectionOut) {
  Problem pr = make_problem(500, 13);
  pr.x[1][2] = pr.x[1][3] = pr.x[1][4] = 0;
  const Evaluated e = evaluate(pr, 0);
  const Compressed c = compressed(pr, 0);
  ASSERT_TRUE(c.r.allFinite());
  ASSERT_TRUE(c.J.allFinite());
  const Eigen::Map<const Eigen::VectorXd> r(e.r.data(), long(e.r.size()));
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
      e.J.data(), long(e.r.size()), e.P);
  EXPECT_NEAR(c.r.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
  EXPECT_EQ(c.J.col(kSourceBlock + 0).norm(), 0.0);  // u1 of the dark source
  EXPECT_EQ(c.J.col(kSourceBlock + 1).norm(), 0.0);
  const Eigen::VectorXd g = J.transpose() * r, gc = c.J.transpose() * c.r;
  EXPECT_LT((gc - g).norm(), 1e-9 * g.norm());
}

}  // namespace
}  // namespace rsibr
