// The split of a bake over ranks: the maps' rows in view-major order (view 0's rows 0..res-1, then
// view 1's, ...), cut into one contiguous run per rank so that each run holds the same number of
// texels inside the sphere-map disc to within one row (a row's cost is its chord: the rows near
// the top and bottom of a disc hold few texels). Views are split between ranks where a cut falls
// inside one, so more ranks than views still share the work.
#pragma once

#include <vector>

namespace rsibr::cluster {

struct RowSpan {
  int view = 0;                    // index into the view set
  int row_begin = 0, row_end = 0;  // rows [row_begin, row_end) of that view's map, non-empty
};

// The rows of `rank` (0 <= rank < ranks), in view-major order; empty when the rank has none (more
// ranks than rows). Over all ranks, every row of every view appears exactly once.
// Throws std::invalid_argument for views < 0, res < 1 or a rank outside [0, ranks).
std::vector<RowSpan> rows_of_rank(int views, int res, int rank, int ranks);

// Texels of row r of a res x res sphere map whose centre lies inside the unit disc (the texels an
// integrator computes), at least 1 so that an empty row still costs its visit.
long row_weight(int r, int res);

}  // namespace rsibr::cluster
