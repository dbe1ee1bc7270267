#pragma once
// Time as the protocol core sees it: a monotonic time point handed in by the
// caller. The core never reads a clock; adapters convert from the OS clock and
// tests drive a fake one.
#include <chrono>
#include <cstdint>

namespace dnbridge {

// A clock type without now(): only its time points and durations are used.
struct MonoClock {
  using rep = std::int64_t;
  using period = std::nano;
  using duration = std::chrono::duration<rep, period>;
  using time_point = std::chrono::time_point<MonoClock>;
  static constexpr bool is_steady = true;
};

using Duration = MonoClock::duration;
using TimePoint = MonoClock::time_point;

// "No deadline": later than any time the process will see.
inline constexpr TimePoint kNever = TimePoint::max();

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;

}  // namespace dnbridge
