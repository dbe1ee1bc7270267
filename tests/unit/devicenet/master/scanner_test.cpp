#include "bridge/devicenet/master/scanner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "bridge/devicenet/wire/duplicate_mac.hpp"

namespace dnbridge::devicenet {
namespace {

MacId mac(unsigned v) { return MacId::from(v).value(); }

class DiscardSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

class StateTimes final : public ScannerObserver {
 public:
  void on_node_state(MacId m, NodeState, NodeState, const std::string&, TimePoint at) override {
    events.push_back({m, at});
  }
  struct Event {
    MacId mac;
    TimePoint at;
  };
  std::vector<Event> events;
};

ScannerConfig three_nodes() {
  ScannerConfig c;
  c.master_mac = mac(0);
  for (unsigned m : {1U, 2U, 3U}) {
    NodeConfig n;
    n.mac = mac(m);
    n.name = "node";
    c.nodes.push_back(n);
  }
  return c;
}

// Starts `scanner` at `now` and runs the duplicate MAC check of the
// master's MAC (two windows, nobody answers); the time it ends.
TimePoint start_scanning(Scanner& scanner, TimePoint now) {
  scanner.start(now);
  for (int i = 0; i < 2; ++i) {
    now = scanner.next_deadline();
    scanner.on_timer(now);
  }
  return now;
}

// Regression (found by the scanner fuzz target): when scanning began, each
// node reported "waiting for the first Allocate" stamped with its staggered
// first attempt (now + 2 ms * index), a time still to come, so the events the
// layer above saw went back in time as the next one arrived.
TEST(Scanner, NodeStartIsReportedWhenItHappensNotAtTheStaggeredFirstAttempt) {
  DiscardSink sink;
  StateTimes observer;
  Scanner scanner(three_nodes(), sink, observer, Logger());
  const TimePoint now = start_scanning(scanner, TimePoint{} + seconds(100));
  ASSERT_EQ(scanner.state(), PortState::kRunning);
  ASSERT_EQ(observer.events.size(), 3u);
  for (const auto& e : observer.events) {
    EXPECT_EQ(e.at, now) << "node " << int{e.mac.value()};
  }
}

class CountingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint at) override {
    if (frame.id == 0x407) checks.push_back(at);  // duplicate MAC ID request, MAC 0
  }
  std::vector<TimePoint> checks;
};

// The bus lost and back during the master's MAC check: the check may have
// gone out on nothing, so it starts again, and scanning waits for it.
TEST(Scanner, ABusBackDuringTheMacCheckStartsTheCheckAgain) {
  CountingSink sink;
  StateTimes observer;
  Scanner scanner(three_nodes(), sink, observer, Logger());
  TimePoint now = TimePoint{} + seconds(100);
  scanner.start(now);
  ASSERT_EQ(sink.checks.size(), 1u);
  now += milliseconds(700);
  scanner.on_timer(now);
  scanner.recheck_mac("the interface is up again", now);
  EXPECT_EQ(scanner.state(), PortState::kCheckingMac);
  ASSERT_EQ(sink.checks.size(), 2u);
  EXPECT_EQ(sink.checks[1], now);
  const TimePoint again = now;
  while (scanner.state() == PortState::kCheckingMac) {
    now = scanner.next_deadline();
    scanner.on_timer(now);
  }
  EXPECT_EQ(scanner.state(), PortState::kRunning);
  EXPECT_EQ(now - again, seconds(2)) << "two windows from the new check";
  EXPECT_EQ(sink.checks.size(), 3u);
}

TEST(Scanner, AChangeOfStateConnectionWithoutARateOrTooLargeIsRefused) {
  DiscardSink sink;
  StateTimes observer;
  ScannerConfig config = three_nodes();
  config.nodes[1].profile.input_connection = InputConnection{};
  EXPECT_NO_THROW(Scanner(config, sink, observer, Logger()));
  config.nodes[1].profile.input_connection->expected_packet_rate = Duration::zero();
  EXPECT_THROW(Scanner(config, sink, observer, Logger()), std::invalid_argument);
  config.nodes[1].profile.input_connection->expected_packet_rate = milliseconds(100);
  config.nodes[1].profile.input_connection->produced_size = Node::kMaxIoSize + 1;
  EXPECT_THROW(Scanner(config, sink, observer, Logger()), std::invalid_argument);
}

TEST(Scanner, ANegativeImmediatePollGapIsRefused) {
  DiscardSink sink;
  StateTimes observer;
  ScannerConfig config = three_nodes();
  config.nodes[1].immediate_poll_min_gap = -milliseconds(1);
  EXPECT_THROW(Scanner(config, sink, observer, Logger()), std::invalid_argument);
  config.nodes[1].immediate_poll_min_gap = Duration::zero();  // every change polled at once
  EXPECT_NO_THROW(Scanner(config, sink, observer, Logger()));
}

// A node the scan list does not have, heard on the bus (powering up at a
// MAC its switch was set to by mistake, or answering another master), is
// noted, and the observer told once; the scan list's nodes and the master's
// own MAC are not. Not heard for ten minutes, it is forgotten.
TEST(Scanner, NodesHeardAtUnconfiguredMacsAreListedUntilNotHeardForTenMinutes) {
  class Heard final : public ScannerObserver {
   public:
    void on_unconfigured_node(MacId m, TimePoint) override { macs.push_back(m.value()); }
    std::vector<unsigned> macs;
  } observer;
  DiscardSink sink;
  Scanner scanner(three_nodes(), sink, observer, Logger());
  TimePoint now = TimePoint{} + seconds(100);
  scanner.start(now);
  const auto powering_up = [](unsigned m) {
    return encode_duplicate_mac(mac(m), DuplicateMacMessage{false, 0, 59, 0x10000 + m}).value();
  };
  // During the master's own MAC check already, and twice (the check's two
  // requests): noted once.
  scanner.on_frame(powering_up(17), now);
  scanner.on_frame(powering_up(17), now + milliseconds(1000));
  scanner.on_frame(powering_up(2), now);  // a configured node powering up
  for (int i = 0; i < 2; ++i) {
    now = scanner.next_deadline();
    scanner.on_timer(now);
  }
  ASSERT_EQ(scanner.state(), PortState::kRunning);
  // A poll response from MAC 40, which some other master polls (Group 1
  // message 15: 0x3C0 | MAC).
  scanner.on_frame(can::CanFrame::make(0x3C0 | 40, Bytes{}).value(), now);
  scanner.on_frame(can::CanFrame::make(0x3C0 | 40, Bytes{}).value(), now);
  EXPECT_EQ(observer.macs, (std::vector<unsigned>{17, 40}));
  const auto heard = scanner.unconfigured_heard(now);
  EXPECT_TRUE(heard.test(17));
  EXPECT_TRUE(heard.test(40));
  EXPECT_FALSE(heard.test(2));
  EXPECT_FALSE(heard.test(0));
  EXPECT_EQ(heard.count(), 2u);

  // Not heard for kUnconfiguredMemory: forgotten (a switch set right since);
  // heard again afterwards: listed and told again.
  const TimePoint later = now + Scanner::kUnconfiguredMemory;
  scanner.on_frame(can::CanFrame::make(0x3C0 | 40, Bytes{}).value(), later - milliseconds(1));
  EXPECT_EQ(scanner.unconfigured_heard(later).count(), 1u);
  EXPECT_TRUE(scanner.unconfigured_heard(later).test(40));
  scanner.on_frame(powering_up(17), later);
  EXPECT_EQ(observer.macs, (std::vector<unsigned>{17, 40, 17}));
  EXPECT_EQ(scanner.unconfigured_heard(later).count(), 2u);
}

// A bit-strobe response (Group 1 message 14) from a MAC the scan list does
// not have, while this port strobes nobody, answers another master: no
// Release is sent to it, and a bus scan does not ask it.
TEST(Scanner, ABitStrobeResponseWhileThePortStrobesNobodyIsAnotherMastersNode) {
  class Recording final : public can::FrameSink {
   public:
    void send(const can::CanFrame& frame, TimePoint) override { ids.push_back(frame.id); }
    std::vector<std::uint32_t> ids;
  } sink;
  StateTimes observer;
  Scanner scanner(three_nodes(), sink, observer, Logger());
  TimePoint now = start_scanning(scanner, TimePoint{} + seconds(100));
  ASSERT_EQ(scanner.state(), PortState::kRunning);
  scanner.on_frame(can::CanFrame::make(0x380 | 40, Bytes{}).value(), now);
  EXPECT_TRUE(scanner.unconfigured_heard(now).test(40));
  ASSERT_TRUE(scanner.scan_bus(now).ok());
  for (int i = 0; i < 100000 && scanner.scanning_bus(); ++i) {
    now = scanner.next_deadline();
    scanner.on_timer(now);
  }
  ASSERT_FALSE(scanner.scanning_bus());
  const std::uint32_t to_40 = 0x406 | (40 << 3);  // Group 2 message 6 to MAC 40
  const std::uint32_t to_41 = 0x406 | (41 << 3);
  EXPECT_EQ(std::count(sink.ids.begin(), sink.ids.end(), to_40), 0);
  EXPECT_GT(std::count(sink.ids.begin(), sink.ids.end(), to_41), 0);  // others are asked
}

}  // namespace
}  // namespace dnbridge::devicenet
