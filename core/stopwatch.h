// Wall-clock seconds since a point on the monotonic clock, for the timings in reports and plans.
#pragma once

#include <chrono>

namespace rsibr {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace rsibr
