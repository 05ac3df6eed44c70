// Parallel loops (TBB). Work is split by rows; results must not depend on the split, so callers
// write disjoint outputs and reduce in a fixed order.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rsibr {

template <class F>
void parallel_for_rows(int rows, F&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r != range.end(); ++r) body(r);
  });
}

}  // namespace rsibr
