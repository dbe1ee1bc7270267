// PortStatusSchedule on a fake clock: the first pass publishes, a change
// publishes at the next pass with its event's time, otherwise once a period.
#include "adapters/port/port_status_schedule.hpp"

#include <gtest/gtest.h>

namespace dnbridge::port {
namespace {

TEST(PortStatusSchedule, FirstPassThenOncePerPeriod) {
  PortStatusSchedule s(seconds(1));
  const TimePoint t0 = TimePoint{} + seconds(5);
  s.start(t0);
  EXPECT_TRUE(s.due(t0, false));
  EXPECT_EQ(s.next_due(), t0);
  s.published(t0);
  EXPECT_FALSE(s.due(t0 + milliseconds(999), false));
  EXPECT_TRUE(s.due(t0 + milliseconds(999), true));
  EXPECT_EQ(s.next_due(), t0 + seconds(1));
  EXPECT_TRUE(s.due(t0 + seconds(1), false));
}

TEST(PortStatusSchedule, AChangeIsDueAtOnceWithItsEventsTime) {
  PortStatusSchedule s(seconds(1));
  const TimePoint t0{};
  s.start(t0);
  s.published(t0);
  s.changed(t0 + milliseconds(300));
  EXPECT_TRUE(s.due(t0 + milliseconds(200), false));
  EXPECT_EQ(s.next_due(), t0);
  // An event stamped later than the pass (a frame's receive time) is the source time.
  EXPECT_EQ(s.source_time(t0 + milliseconds(200)), t0 + milliseconds(300));
  EXPECT_EQ(s.source_time(t0 + milliseconds(400)), t0 + milliseconds(400));
  s.published(t0 + milliseconds(400));
  EXPECT_EQ(s.next_due(), t0 + milliseconds(1400));
  // A change with no time of its own keeps the last event's.
  s.changed();
  EXPECT_TRUE(s.due(t0 + milliseconds(500), false));
  EXPECT_EQ(s.source_time(t0), t0 + milliseconds(300));
}

}  // namespace
}  // namespace dnbridge::port
