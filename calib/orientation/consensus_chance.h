// Whether a view's matched features agree beyond what chance gives: the test that keeps a view
// out of the solve when its "inliers" are no more than random matches could produce.
#pragma once

#include "calib/orientation/orientation_solve.h"

#include <optional>
#include <vector>

namespace rsibr {

// Per view: how many of its observation pairs (with every other view, track by track) agree
// within consensus_deg at the solve's rotations, and how many chance alone would make agree. A
// pair inside the search's gate under the guess could have been paired by chance anywhere in that
// disc: it agrees by chance with the share of the gate's disc that lies within consensus_deg of
// where the solution puts it, (consensus / gate)^2 when guess and solution coincide, falling to 0
// when they lie gate + consensus apart (approximated linearly between); any other pair, matched
// over the whole sphere, with the share of the sphere a consensus cap covers. The p-value is the
// Poisson tail of the agreeing count at the expected count (the Poisson's variance bounds the sum
// of unequal Bernoullis', so it errs toward "chance").
//   Without a guess (`fitted`: the rotations come from these matches alone), a rotation fitted to
// any two of a view's N pairs makes those two agree whatever they are: the count is taken beyond
// that minimal set, and the tail is bounded over the N (N - 1) / 2 sets a consensus search tries
// (Bonferroni, again toward "chance"). Seven pairs need four agreeing.
struct ChanceTest {
  int matched = 0;      // observation pairs with the other oriented views
  int agreeing = 0;     // of those: within consensus_deg at the solve's rotations
  double expected = 0;  // what chance gives (with `fitted`, the minimal set's 2 included)
  double p_value = 1;   // of seeing `agreeing` by chance alone
};

// P(X >= k) for X ~ Poisson(lambda); 1 for k <= 0.
double poisson_tail(double lambda, int k);

// Per view of `s` (its oriented views; a view left out gets matched = 0): `guess` per view or
// empty (no search), angles in degrees, `fitted` as above.
std::vector<ChanceTest> consensus_against_chance(const std::vector<DirectionObservation>& obs,
                                                 const OrientationSolution& s,
                                                 const std::vector<std::optional<Mat3>>& guess, double consensus_deg,
                                                 double gate_deg, bool fitted);

}  // namespace rsibr
