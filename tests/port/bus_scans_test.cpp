// BusScans on a fake clock: one scan at a time, its waiters answered when
// it ends, a repeated request waiting once, the last complete scan given
// again within the holdoff, and refusals when the bus is lost, too many
// wait, or the master does not start the scan.
#include "adapters/port/bus_scans.hpp"

#include <gtest/gtest.h>

#include "port/component_fixture.hpp"

namespace dnbridge::port {
namespace {

using rack::TransactionStatus;

ScanCall call(std::string who, std::uint32_t txid) { return ScanCall{std::move(who), txid}; }

devicenet::BusScan scan(TimePoint started, TimePoint finished, std::string error = {}) {
  devicenet::BusScan s;
  s.started = started;
  s.finished = finished;
  s.error = std::move(error);
  return s;
}

class BusScansTest : public ::testing::Test {
 protected:
  test::CountingPublisher publisher;
  BusScans scans{"can0", publisher};
  const TimePoint t0 = TimePoint{} + seconds(100);
};

TEST_F(BusScansTest, WaitersAreAnsweredWhenTheScanEnds) {
  EXPECT_TRUE(scans.request(call("a", 1), false, BusState::kErrorActive, t0));
  // The scan runs: more wait for it; a request written again waits once.
  EXPECT_FALSE(scans.request(call("b", 7), true, BusState::kErrorActive, t0 + seconds(1)));
  EXPECT_FALSE(scans.request(call("a", 1), true, BusState::kErrorActive, t0 + seconds(2)));
  EXPECT_EQ(scans.waiting(), 2u);
  EXPECT_TRUE(publisher.scans.empty());

  scans.on_bus_scan(scan(t0, t0 + seconds(4)), t0 + seconds(4));
  ASSERT_EQ(publisher.scans.size(), 2u);
  EXPECT_EQ(publisher.scans[0].requester, "a");
  EXPECT_EQ(publisher.scans[1].txid, 7u);
  EXPECT_EQ(publisher.scans[0].status, TransactionStatus::kSuccess);
  EXPECT_EQ(publisher.scans[0].duration, seconds(4));
  EXPECT_EQ(publisher.scans[0].message, "port can0: bus scanned in 4.0 s");
  EXPECT_EQ(scans.waiting(), 0u);
}

TEST_F(BusScansTest, WithinTheHoldoffTheLastScanIsGivenAgain) {
  ASSERT_TRUE(scans.request(call("a", 1), false, BusState::kErrorActive, t0));
  scans.on_bus_scan(scan(t0, t0 + seconds(2)), t0 + seconds(2));
  const TimePoint later = t0 + seconds(2) + BusScans::kHoldoff - milliseconds(1);
  EXPECT_FALSE(scans.request(call("b", 2), false, BusState::kErrorActive, later));
  ASSERT_EQ(publisher.scans.size(), 2u);
  EXPECT_EQ(publisher.scans[1].age, BusScans::kHoldoff - milliseconds(1));
  EXPECT_EQ(publisher.scans[1].message,
            "port can0: the bus scan of 30.0 s ago (at most one every 30 s)");
  // Past it, a new scan.
  EXPECT_TRUE(scans.request(call("c", 3), false, BusState::kErrorActive,
                            t0 + seconds(2) + BusScans::kHoldoff));
}

TEST_F(BusScansTest, AScanCutShortIsNotGivenAgain) {
  ASSERT_TRUE(scans.request(call("a", 1), false, BusState::kErrorActive, t0));
  scans.on_bus_scan(scan(t0, t0 + seconds(1), "the port stopped"), t0 + seconds(1));
  ASSERT_EQ(publisher.scans.size(), 1u);
  EXPECT_EQ(publisher.scans[0].status, TransactionStatus::kPortOffline);
  EXPECT_EQ(publisher.scans[0].message, "port can0: bus scan cut short (the port stopped)");
  EXPECT_TRUE(scans.request(call("b", 2), false, BusState::kErrorActive, t0 + seconds(2)));
}

TEST_F(BusScansTest, RefusedWhenTheBusIsLostTooManyWaitOrTheMasterWillNot) {
  EXPECT_FALSE(scans.request(call("a", 1), false, BusState::kBusOff, t0));
  ASSERT_EQ(publisher.scans.size(), 1u);
  EXPECT_EQ(publisher.scans[0].status, TransactionStatus::kPortOffline);
  EXPECT_EQ(publisher.scans[0].message, "port can0: the bus is bus-off: no bus scan");

  ASSERT_TRUE(scans.request(call("b", 2), false, BusState::kErrorActive, t0));
  scans.start_refused("stopped: not started");
  ASSERT_EQ(publisher.scans.size(), 2u);
  EXPECT_EQ(publisher.scans[1].requester, "b");
  EXPECT_EQ(publisher.scans[1].message,
            "port can0 is not scanning its nodes (stopped: not started): no bus scan");
  EXPECT_EQ(scans.waiting(), 0u);

  for (std::uint32_t i = 0; i < BusScans::kMaxWaiters; ++i) {
    (void)scans.request(call("w", i), i > 0, BusState::kErrorActive, t0);
  }
  EXPECT_FALSE(scans.request(call("late", 1), true, BusState::kErrorActive, t0));
  ASSERT_EQ(publisher.scans.size(), 3u);
  EXPECT_EQ(publisher.scans[2].status, TransactionStatus::kOutOfBuffers);
  EXPECT_EQ(scans.waiting(), BusScans::kMaxWaiters);
}

}  // namespace
}  // namespace dnbridge::port
