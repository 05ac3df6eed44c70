// The test that keeps a view out when its matches agree no better than chance
// (calib/orientation/consensus_chance.h): a rotation fitted to random matches makes two of them
// agree, which is no evidence; four of seven agreeing is; under a search's gate chance is larger.
#include "calib/orientation/consensus_chance.h"

#include "random_directions.h"

#include <gtest/gtest.h>

#include <random>

namespace rsibr {
namespace {

// Two views at identity rotations; `agreeing` tracks seen in the same direction by both, the
// rest of `tracks` paired with unrelated directions.
std::vector<DirectionObservation> two_views(int tracks, int agreeing, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<DirectionObservation> obs;
  for (int t = 0; t < tracks; ++t) {
    const Vec3 a = testing::random_direction(rng);
    const Vec3 b = t < agreeing ? a : testing::random_direction(rng);
    obs.push_back({0, t, a, 1e-3});
    obs.push_back({1, t, b, 1e-3});
  }
  return obs;
}

OrientationSolution identity_solution() {
  OrientationSolution s;
  s.oriented = {1, 1};
  s.world_from_cam = {Mat3::Identity(), Mat3::Identity()};
  return s;
}

TEST(ConsensusChance, PoissonTailIsOneAtZeroAndMatchesTheSeriesElsewhere) {
  EXPECT_EQ(poisson_tail(0.5, 0), 1.0);
  EXPECT_EQ(poisson_tail(0.0, 1), 0.0);
  EXPECT_NEAR(poisson_tail(0.5, 1), 1 - std::exp(-0.5), 1e-15);
  EXPECT_NEAR(poisson_tail(2.0, 3), 1 - std::exp(-2.0) * (1 + 2 + 2), 1e-14);
}

TEST(ConsensusChance, ARotationFittedToTwoOfSevenRandomMatchesIsChance) {
  const std::vector<ChanceTest> c = consensus_against_chance(two_views(7, 2, 1), identity_solution(), {}, 2, 4, true);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[1].matched, 7);
  EXPECT_EQ(c[1].agreeing, 2);
  EXPECT_GT(c[1].p_value, 1e-3);
  // Not fitted to them (an independent rotation), two agreeing on the whole sphere would be rare.
  EXPECT_LT(consensus_against_chance(two_views(7, 2, 1), identity_solution(), {}, 2, 4, false)[1].p_value, 1e-3);
}

TEST(ConsensusChance, FourOfSevenAgreeingIsBeyondChance) {
  const std::vector<ChanceTest> c = consensus_against_chance(two_views(7, 4, 2), identity_solution(), {}, 2, 4, true);
  EXPECT_EQ(c[1].agreeing, 4);
  EXPECT_LT(c[1].p_value, 1e-3);
  EXPECT_GT(consensus_against_chance(two_views(7, 3, 2), identity_solution(), {}, 2, 4, true)[1].p_value, 1e-3);
}

TEST(ConsensusChance, UnderTheSearchsGateAgreementIsMoreLikelyByChance) {
  // Every pair inside a 4-degree gate of the guess: a quarter of them land within 2 degrees by
  // chance, so 4 of 16 agreeing is chance, 14 of 16 is not.
  const std::vector<std::optional<Mat3>> guess = {Mat3::Identity(), Mat3::Identity()};
  std::mt19937_64 rng(3);
  auto gated = [&](int agreeing) {
    std::vector<DirectionObservation> obs;
    for (int t = 0; t < 16; ++t) {
      const Vec3 a = testing::random_direction(rng);
      const Vec3 off = a.unitOrthogonal();
      const Vec3 b = (a + std::tan((t < agreeing ? 0.5 : 3.0) * kDeg) * off).normalized();
      obs.push_back({0, t, a, 1e-3});
      obs.push_back({1, t, b, 1e-3});
    }
    return consensus_against_chance(obs, identity_solution(), guess, 2, 4, false)[1];
  };
  const ChanceTest few = gated(4), most = gated(14);
  EXPECT_NEAR(few.expected, 4.0, 1e-9);
  EXPECT_GT(few.p_value, 1e-3);
  EXPECT_LT(most.p_value, 1e-3);
}

}  // namespace
}  // namespace rsibr
