#pragma once
// The adapters' clock: the steady (monotonic) clock as the core's TimePoint.
// Every port runs on it; CAN receive times are moved onto it; DDS source
// timestamps are mapped from it to the wall clock (daemon::WallClock).
#include <chrono>

#include "bridge/common/time.hpp"

namespace dnbridge::port {

inline TimePoint steady_now() {
  return TimePoint(
      std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now().time_since_epoch()));
}

inline std::chrono::steady_clock::time_point to_steady(TimePoint t) {
  return std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(t.time_since_epoch()));
}

}  // namespace dnbridge::port
