#include "calib/orientation/consensus_chance.h"

#include "core/vec.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace rsibr {

double poisson_tail(double lambda, int k) {
  if (k <= 0) return 1;
  if (!(lambda > 0)) return 0;
  // 1 - P(X <= k - 1), summed in log space.
  double below = 0;
  for (int i = 0; i < k; ++i) below += std::exp(i * std::log(lambda) - lambda - std::lgamma(i + 1.0));
  return std::clamp(1 - below, 0.0, 1.0);
}

std::vector<ChanceTest> consensus_against_chance(const std::vector<DirectionObservation>& obs,
                                                 const OrientationSolution& s,
                                                 const std::vector<std::optional<Mat3>>& guess, double consensus_deg,
                                                 double gate_deg, bool fitted) {
  const std::size_t views = s.oriented.size();
  std::map<int, std::vector<const DirectionObservation*>> tracks;
  for (const DirectionObservation& o : obs) tracks[o.feature].push_back(&o);
  const double c = consensus_deg * kPi / 180, g = gate_deg * kPi / 180;
  const double p_in = std::min(1.0, std::pow(c / g, 2)), p_sphere = (1 - std::cos(c)) / 2;
  std::vector<ChanceTest> out(views);
  std::vector<double> lambda(views, 0);
  for (const auto& [id, seen] : tracks)
    for (const DirectionObservation* x : seen)
      for (const DirectionObservation* y : seen) {
        const std::size_t a = std::size_t(x->view), b = std::size_t(y->view);
        if (a == b || !s.oriented[a] || !s.oriented[b]) continue;
        ++out[a].matched;
        const Vec3 solved = s.world_from_cam[b].transpose() * s.world_from_cam[a] * x->direction;
        out[a].agreeing += angle_between(solved, y->direction) < c;
        double p = p_sphere;
        if (a < guess.size() && b < guess.size() && guess[a] && guess[b]) {
          const Vec3 guessed = guess[b]->transpose() * *guess[a] * x->direction;
          if (angle_between(guessed, y->direction) < g) {
            const double apart = angle_between(guessed, solved);
            p = std::max(p, p_in * std::clamp((g + c - apart) / (g + c - std::max(c, g - c)), 0.0, 1.0));
          }
        }
        lambda[a] += p;
      }
  for (std::size_t v = 0; v < views; ++v) {
    out[v].expected = lambda[v];
    if (fitted) {
      const double n = out[v].matched, minimal_sets = std::max(1.0, n * (n - 1) / 2);
      out[v].expected += std::min(2, out[v].matched);  // the minimal set agrees by construction
      out[v].p_value = std::min(1.0, minimal_sets * poisson_tail(lambda[v], out[v].agreeing - 2));
    } else {
      out[v].p_value = poisson_tail(lambda[v], out[v].agreeing);
    }
  }
  return out;
}

}  // namespace rsibr
