// Two images equal bit for bit (size, type and every byte): the round-trip tests' criterion.
#pragma once

#include <opencv2/core.hpp>

#include <cstring>

namespace rsibr::testing {

inline bool bitwise_equal(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int r = 0; r < a.rows; ++r)
    if (std::memcmp(a.ptr(r), b.ptr(r), a.cols * a.elemSize()) != 0) return false;
  return true;
}

}  // namespace rsibr::testing
