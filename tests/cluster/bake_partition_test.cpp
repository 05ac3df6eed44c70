#include "cluster/bake_partition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr::cluster {
namespace {

long brute_row_weight(int r, int res) {
  const double y = 1.0 - (2.0 * r + 1.0) / res;
  long n = 0;
  for (int c = 0; c < res; ++c) {
    const double x = (2.0 * c + 1.0) / res - 1.0;
    n += x * x + y * y < 1.0;
  }
  return std::max(1L, n);
}

TEST(BakePartition, RowWeightIsTheCountOfTexelCentresInsideTheDisc) {
  for (int res = 1; res <= 130; ++res)
    for (int r = 0; r < res; ++r)
      ASSERT_EQ(row_weight(r, res), brute_row_weight(r, res)) << "res " << res << " row " << r;
  EXPECT_EQ(row_weight(0, 1), 1);  // the one texel of a 1x1 map sits at the centre
  EXPECT_EQ(row_weight(0, 2), 2);
}

TEST(BakePartition, EveryRowOfEveryViewBelongsToExactlyOneRankInViewMajorOrder) {
  for (int views : {0, 1, 4, 12, 162})
    for (int res : {1, 2, 7, 64})
      for (int ranks : {1, 2, 3, 8, 64, 1000}) {
        std::vector<int> owner(std::size_t(views) * res, -1);
        long last = -1;  // runs are contiguous and in rank order
        for (int k = 0; k < ranks; ++k)
          for (const RowSpan& s : rows_of_rank(views, res, k, ranks)) {
            ASSERT_LT(s.row_begin, s.row_end);
            ASSERT_GE(s.row_begin, 0);
            ASSERT_LE(s.row_end, res);
            for (int r = s.row_begin; r < s.row_end; ++r) {
              const long g = long(s.view) * res + r;
              ASSERT_EQ(owner[std::size_t(g)], -1) << "row given twice";
              ASSERT_GT(g, last) << "not view-major";
              owner[std::size_t(g)] = k;
              last = g;
            }
          }
        ASSERT_TRUE(std::count(owner.begin(), owner.end(), -1) == 0)
            << views << " views, res " << res << ", " << ranks << " ranks: a row nobody integrates";
      }
}

TEST(BakePartition, RanksGetEqualTexelCountsToWithinOneRow) {
  for (int views : {1, 5, 42})
    for (int res : {16, 100})
      for (int ranks : {2, 3, 7, 40}) {
        long total = 0, widest = 0;
        for (int r = 0; r < res; ++r) {
          total += row_weight(r, res);
          widest = std::max(widest, row_weight(r, res));
        }
        total *= views;
        for (int k = 0; k < ranks; ++k) {
          long mine = 0;
          for (const RowSpan& s : rows_of_rank(views, res, k, ranks))
            for (int r = s.row_begin; r < s.row_end; ++r) mine += row_weight(r, res);
          EXPECT_LE(std::abs(double(mine) - double(total) / ranks), double(widest))
              << views << " views, res " << res << ", rank " << k << " of " << ranks;
        }
      }
}

TEST(BakePartition, MoreRanksThanRowsLeavesSomeRanksIdleAndNoneDoubled) {
  int busy = 0;
  for (int k = 0; k < 50; ++k) busy += !rows_of_rank(1, 4, k, 50).empty();
  EXPECT_EQ(busy, 4);
}

TEST(BakePartition, ARankOutsideTheJobOrAnEmptyMapIsAnError) {
  EXPECT_THROW(rows_of_rank(4, 16, 2, 2), std::invalid_argument);
  EXPECT_THROW(rows_of_rank(4, 16, -1, 2), std::invalid_argument);
  EXPECT_THROW(rows_of_rank(4, 0, 0, 1), std::invalid_argument);
  EXPECT_THROW(rows_of_rank(-1, 16, 0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr::cluster
