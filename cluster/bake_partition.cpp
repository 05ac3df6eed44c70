#include "cluster/bake_partition.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rsibr::cluster {

// Row r's texel centres have y = 1 - (2r+1)/res and x = (2c+1)/res - 1; they are inside the disc
// when x^2 + y^2 < 1, i.e. |2c+1-res| < res*sqrt(1-y^2): counted exactly, column by column would
// cost res per row, so the chord is solved for and the count checked at its two ends.
long row_weight(int r, int res) {
  const double y = 1.0 - (2.0 * r + 1.0) / res;
  long count = 0;
  const double half = 1.0 - y * y;
  if (half > 0) {
    const double w = res * std::sqrt(half);  // |2c+1-res| < w
    // c from ceil((res-1-w)/2) to floor((res-1+w)/2), with the ends strict.
    long lo = long(std::ceil((res - 1 - w) / 2.0)), hi = long(std::floor((res - 1 + w) / 2.0));
    auto inside = [&](long c) {
      const double x = (2.0 * c + 1.0) / res - 1.0;
      return x * x + y * y < 1.0;
    };
    while (lo <= hi && (lo < 0 || !inside(lo))) ++lo;
    while (hi >= lo && (hi >= res || !inside(hi))) --hi;
    count = hi >= lo ? hi - lo + 1 : 0;
  }
  return std::max(1L, count);
}

std::vector<RowSpan> rows_of_rank(int views, int res, int rank, int ranks) {
  if (views < 0 || res < 1 || ranks < 1 || rank < 0 || rank >= ranks)
    throw std::invalid_argument("bake partition: rank " + std::to_string(rank) + " of " + std::to_string(ranks) + ", " +
                                std::to_string(views) + " views of " + std::to_string(res) + " rows");
  std::vector<long> weight(static_cast<std::size_t>(res));
  long per_map = 0;
  for (int r = 0; r < res; ++r) per_map += weight[std::size_t(r)] = row_weight(r, res);
  // Global row g (view g / res, row g % res) is rank k's when the weight before it, W_<g, satisfies
  // k*W <= ranks*W_<g < (k+1)*W: integer arithmetic, so the cuts do not depend on rounding.
  const long double total = (long double)per_map * views;
  std::vector<RowSpan> spans;
  long double before = 0;
  for (int v = 0; v < views; ++v) {
    for (int r = 0; r < res; ++r) {
      const long double scaled = before * ranks;
      const bool mine = scaled >= total * rank && scaled < total * (rank + 1);
      before += weight[std::size_t(r)];
      if (!mine) continue;
      if (!spans.empty() && spans.back().view == v && spans.back().row_end == r)
        ++spans.back().row_end;
      else
        spans.push_back({v, r, r + 1});
    }
  }
  return spans;
}

}  // namespace rsibr::cluster
