#pragma once
// Time at the DDS boundary. Durations are the core's dnbridge::Duration
// (nanoseconds). Source timestamps are wall-clock time, as DDS defines them,
// so they get their own type, distinct from the core's monotonic TimePoint.
#include <dds/dds.h>

#include <chrono>

#include "bridge/common/time.hpp"

namespace dnbridge::dds {

using Timestamp = std::chrono::sys_time<std::chrono::nanoseconds>;

// Duration::max() has the same count as DDS_INFINITY (INT64_MAX).
inline constexpr Duration kInfinite = Duration::max();
static_assert(kInfinite.count() == DDS_INFINITY);

inline constexpr dds_duration_t to_dds(Duration d) noexcept { return d.count(); }
inline constexpr dds_time_t to_dds(Timestamp t) noexcept { return t.time_since_epoch().count(); }
inline constexpr Timestamp from_dds(dds_time_t t) noexcept {
  return Timestamp(std::chrono::nanoseconds(t));
}

// Cyclone's own clock, the one dds_write stamps samples with.
inline Timestamp dds_now() noexcept { return from_dds(dds_time()); }

}  // namespace dnbridge::dds
