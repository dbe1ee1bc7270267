// BusMetrics on a fake clock: figures over whole periods only, bus load from
// the bits on the wire, the scan cycle from the online nodes' polls, and a
// node configured again counting its polls anew.
#include "adapters/port/bus_metrics.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "port/component_fixture.hpp"

namespace dnbridge::port {
namespace {

using test::mac;

BusCounters bus(std::uint64_t frames, std::uint64_t bits) {
  BusCounters c;
  c.frames = frames;
  c.bits = bits;
  return c;
}

TEST(BusMetrics, MeasuresOverWholePeriodsOnly) {
  BusMetrics m(seconds(1));
  const TimePoint t0 = TimePoint{} + seconds(10);
  m.start(t0);
  std::vector<BusMetrics::NodePolls> polls{{mac(1), true, 0}};
  // Within the period: nothing measured, the figures stay.
  m.measure_if_due(bus(500, 50'000), 125'000, polls, t0 + milliseconds(999));
  EXPECT_EQ(m.figures().frames_per_second, 0.0);

  polls[0].polls = 100;
  m.measure_if_due(bus(1000, 62'500), 125'000, polls, t0 + seconds(2));
  EXPECT_DOUBLE_EQ(m.figures().frames_per_second, 500.0);
  EXPECT_DOUBLE_EQ(m.figures().bus_load_percent, 25.0);
  EXPECT_DOUBLE_EQ(m.figures().scan_cycle_ms, 20.0);
}

TEST(BusMetrics, ScanCycleIsTheMeanOfTheOnlineNodesThatWerePolled) {
  BusMetrics m(seconds(1));
  const TimePoint t0{};
  m.start(t0);
  std::vector<BusMetrics::NodePolls> polls{
      {mac(1), true, 100}, {mac(2), true, 50}, {mac(3), false, 10}, {mac(4), true, 0}};
  m.measure_if_due(bus(0, 0), 0, polls, t0 + seconds(1));
  EXPECT_DOUBLE_EQ(m.figures().scan_cycle_ms, 15.0);  // (10 + 20) / 2
  EXPECT_EQ(m.figures().bus_load_percent, 0.0);       // no bitrate known
  // The next period counts from the polls seen at this one.
  polls[0].polls = 150;
  polls[1].polls = 50;
  m.measure_if_due(bus(0, 0), 0, polls, t0 + seconds(2));
  EXPECT_DOUBLE_EQ(m.figures().scan_cycle_ms, 20.0);
}

TEST(BusMetrics, ANodeRestartedCountsItsPollsFromZero) {
  BusMetrics m(seconds(1));
  const TimePoint t0{};
  m.start(t0);
  std::vector<BusMetrics::NodePolls> polls{{mac(7), true, 1000}};
  m.measure_if_due(bus(0, 0), 0, polls, t0 + seconds(1));
  // Configured again: the master's node counts from zero.
  m.restart(mac(7));
  polls[0].polls = 25;
  m.measure_if_due(bus(0, 0), 0, polls, t0 + seconds(2));
  EXPECT_DOUBLE_EQ(m.figures().scan_cycle_ms, 40.0);
}

}  // namespace
}  // namespace dnbridge::port
