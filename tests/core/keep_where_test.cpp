// core/keep_where.h: the kept entries stay whole and in order, including those that do not move (a
// std::vector moved onto itself is emptied: orient's leaving a view out once did that).
#include "core/keep_where.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace rsibr {
namespace {

TEST(KeepWhere, KeptEntriesStayWholeAndInOrder) {
  std::vector<std::vector<int>> v = {{1}, {2, 2}, {3, 3, 3}, {4, 4, 4, 4}};
  keep_where(v, std::vector<char>{1, 0, 1, 1});
  EXPECT_EQ(v, (std::vector<std::vector<int>>{{1}, {3, 3, 3}, {4, 4, 4, 4}}));
}

TEST(KeepWhere, KeepingEverythingChangesNothing) {
  const std::vector<std::string> before = {"a", "bb", "ccc"};
  std::vector<std::string> v = before;
  keep_where(v, std::vector<char>{1, 1, 1});
  EXPECT_EQ(v, before);
  keep_where(v, std::vector<char>{0, 0, 0});
  EXPECT_TRUE(v.empty());
}

TEST(KeepWhere, AMaskOfAnotherSizeIsAnError) {
  std::vector<int> v = {1, 2};
  EXPECT_THROW(keep_where(v, std::vector<char>{1}), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
