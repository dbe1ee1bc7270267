#include "adapters/sim/bus/virtual_bus.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <functional>
#include <string>
#include <vector>

#include "support/bytes.hpp"

namespace dnbridge::sim {
namespace {

using test::frame;

constexpr TimePoint at(Duration d) { return TimePoint(d); }

struct Reception {
  std::string node;
  can::CanFrame frame;
  TimePoint rx_time;
  friend bool operator==(const Reception&, const Reception&) = default;
};

// A node that records what it hears into a log shared by all nodes, so tests
// can check the global order, and can answer through a callback.
class RecordingPort : public BusPort {
 public:
  RecordingPort(std::string name, std::vector<Reception>& log)
      : name_(std::move(name)), log_(log) {}
  void on_frame(const can::CanFrame& f, TimePoint rx_time) override {
    log_.push_back({name_, f, rx_time});
    ++count_;
    if (reply) reply(f, rx_time);
  }
  std::size_t count() const { return count_; }
  std::vector<Reception> heard() const {
    std::vector<Reception> mine;
    for (const Reception& r : log_) {
      if (r.node == name_) mine.push_back(r);
    }
    return mine;
  }
  std::function<void(const can::CanFrame&, TimePoint)> reply;

 private:
  std::string name_;
  std::vector<Reception>& log_;
  std::size_t count_ = 0;
};

std::vector<std::uint32_t> ids(const std::vector<Reception>& rs) {
  std::vector<std::uint32_t> out;
  for (const Reception& r : rs) out.push_back(r.frame.id);
  return out;
}

std::vector<TimePoint> times(const std::vector<Reception>& rs) {
  std::vector<TimePoint> out;
  for (const Reception& r : rs) out.push_back(r.rx_time);
  return out;
}

class BusTest : public ::testing::Test {
 protected:
  std::vector<Reception> log_;
  RecordingPort a_{"a", log_}, b_{"b", log_}, c_{"c", log_}, listener_{"listener", log_};
};

// ---------------------------------------------------------------- ideal mode

TEST_F(BusTest, IdealModeDeliversAtSendTimeInSendOrder) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  bus.attach(listener_);
  const TimePoint t = at(milliseconds(3));
  EXPECT_EQ(bus.next_event(), kNever);

  bus.sink(a).send(frame(0x300, {1}), t);
  bus.sink(b).send(frame(0x100, {2}), t);
  bus.sink(a).send(frame(0x200, {3}), t);
  EXPECT_EQ(bus.next_event(), t);
  bus.advance(t - microseconds(1));
  EXPECT_EQ(listener_.count(), 0u);

  bus.advance(t);
  // Send order, not identifier order: no arbitration in ideal mode.
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x300, 0x100, 0x200}));
  EXPECT_EQ(times(listener_.heard()), (std::vector<TimePoint>{t, t, t}));
  // Nobody hears its own frames.
  EXPECT_EQ(ids(a_.heard()), (std::vector<std::uint32_t>{0x100}));
  EXPECT_EQ(ids(b_.heard()), (std::vector<std::uint32_t>{0x300, 0x200}));
  EXPECT_EQ(bus.next_event(), kNever);
  EXPECT_EQ(bus.stats().delivered, 3u);
  EXPECT_EQ(bus.stats().receptions, 6u);
  EXPECT_EQ(bus.stats().busy_time, Duration::zero());
  EXPECT_EQ(bus.frames_with_id(0x300), 1u);
}

TEST_F(BusTest, IdealModeFutureFrameWaitsForItsTime) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  bus.send(a, frame(0x010, {}), at(milliseconds(5)));
  bus.send(a, frame(0x011, {}), at(milliseconds(1)));  // FIFO: behind the first
  bus.advance(at(milliseconds(4)));
  EXPECT_EQ(listener_.count(), 0u);
  bus.advance(at(milliseconds(5)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x010, 0x011}));
  EXPECT_EQ(times(listener_.heard()),
            (std::vector<TimePoint>{at(milliseconds(5)), at(milliseconds(5))}));
}

// ---------------------------------------------------------------- timed mode

TEST_F(BusTest, ArbitrationSendsLowestIdentifierFirst) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_), c = bus.attach(c_);
  bus.attach(listener_);
  const can::CanFrame fa = frame(0x300, {1, 2, 3}), fb = frame(0x100, {4}),
                      fc = frame(0x200, {5, 6, 7, 8, 9, 10, 11, 12});
  const TimePoint t0 = at(milliseconds(1));
  bus.send(a, fa, t0);
  bus.send(b, fb, t0);
  bus.send(c, fc, t0);

  const Duration db = can::frame_duration(fb, can::kBitrate500k),
                 dc = can::frame_duration(fc, can::kBitrate500k),
                 da = can::frame_duration(fa, can::kBitrate500k);
  EXPECT_EQ(bus.next_event(), t0);
  bus.advance(t0);
  EXPECT_TRUE(bus.busy());
  EXPECT_EQ(bus.next_event(), t0 + db);

  bus.advance(at(seconds(1)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x100, 0x200, 0x300}));
  EXPECT_EQ(times(listener_.heard()),
            (std::vector<TimePoint>{t0 + db, t0 + db + dc, t0 + db + dc + da}));
  EXPECT_EQ(bus.stats().busy_time, db + dc + da);
  EXPECT_EQ(bus.stats().bits,
            std::uint64_t{can::frame_bits(fa)} + can::frame_bits(fb) + can::frame_bits(fc));
  EXPECT_EQ(bus.stats().collisions, 0u);
  EXPECT_FALSE(bus.busy());
}

TEST_F(BusTest, ExactDeliveryTimeOfOneFrame) {
  // ID 0, no data: 53 bits (can_timing_test), 8 us each at 125k = 424 us.
  VirtualBus bus({.bitrate = can::kBitrate125k});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  bus.send(a, frame(0x000, {}), at(Duration::zero()));
  bus.advance(at(microseconds(423)));
  EXPECT_EQ(listener_.count(), 0u);
  EXPECT_EQ(bus.next_event(), at(microseconds(424)));
  bus.advance(at(microseconds(424)));
  ASSERT_EQ(listener_.count(), 1u);
  EXPECT_EQ(listener_.heard()[0].rx_time, at(microseconds(424)));
}

TEST_F(BusTest, BusyBusDelaysEvenAHigherPriorityFrame) {
  VirtualBus bus({.bitrate = can::kBitrate250k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_), c = bus.attach(c_);
  bus.attach(listener_);
  const can::CanFrame fa = frame(0x400, {1, 2, 3, 4, 5, 6, 7, 8}), fb = frame(0x100, {}),
                      fc = frame(0x050, {});
  const Duration da = can::frame_duration(fa, can::kBitrate250k),
                 db = can::frame_duration(fb, can::kBitrate250k),
                 dc = can::frame_duration(fc, can::kBitrate250k);
  bus.send(a, fa, at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  // Both queued while 0x400 is on the wire; no preemption, then 0x050 wins.
  bus.send(b, fb, at(microseconds(10)));
  bus.advance(at(microseconds(20)));
  bus.send(c, fc, at(microseconds(30)));
  bus.advance(at(seconds(1)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x400, 0x050, 0x100}));
  EXPECT_EQ(times(listener_.heard()),
            (std::vector<TimePoint>{at(da), at(da + dc), at(da + dc + db)}));
}

TEST_F(BusTest, FrameQueuedOnIdleBusStartsAtItsSendTime) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  const can::CanFrame f = frame(0x123, {0xAA});
  bus.advance(at(milliseconds(7)));
  bus.send(a, f, at(milliseconds(7)));
  bus.advance(at(seconds(1)));
  ASSERT_EQ(listener_.count(), 1u);
  EXPECT_EQ(listener_.heard()[0].rx_time,
            at(milliseconds(7)) + can::frame_duration(f, can::kBitrate500k));
}

TEST_F(BusTest, EqualIdentifiersFromTwoNodesCountAsCollision) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  bus.attach(listener_);
  bus.send(b, frame(0x200, {0xB}), at(Duration::zero()));
  bus.send(a, frame(0x200, {0xA}), at(Duration::zero()));
  bus.advance(at(seconds(1)));
  ASSERT_EQ(listener_.count(), 2u);
  EXPECT_EQ(listener_.heard()[0].frame.data[0], 0xA);  // lower handle first
  EXPECT_EQ(listener_.heard()[1].frame.data[0], 0xB);
  EXPECT_EQ(bus.stats().collisions, 1u);
}

TEST_F(BusTest, BusLoadOfAPeriodicFrame) {
  // One 53-bit frame (424 us at 125k) every millisecond: 42.4 % load.
  VirtualBus bus({.bitrate = can::kBitrate125k});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  for (int i = 0; i < 10; ++i) {
    const TimePoint t = at(milliseconds(i));
    bus.advance(t);
    bus.send(a, frame(0x000, {}), t);
  }
  bus.advance(at(milliseconds(10)));
  EXPECT_EQ(listener_.count(), 10u);
  EXPECT_EQ(bus.stats().busy_time, microseconds(4240));
  EXPECT_EQ(bus.stats().bits, 530u);
  EXPECT_DOUBLE_EQ(bus.bus_load(at(milliseconds(10))), 0.424);
  EXPECT_DOUBLE_EQ(bus.bus_load(at(milliseconds(20))), 0.212);

  // A new window in the middle of a frame counts only the part inside it.
  bus.reset_load_window(at(microseconds(10200)));
  bus.send(a, frame(0x000, {}), at(milliseconds(10)));  // clamped to bus time 10 ms
  bus.advance(at(microseconds(10300)));
  // Busy from 10.2 to 10.3 ms, the window is 0.1 ms long.
  EXPECT_DOUBLE_EQ(bus.bus_load(at(microseconds(10300))), 1.0);
  bus.advance(at(milliseconds(11)));
  // 10.2..10.424 busy in 10.2..11.0: 224 / 800.
  EXPECT_DOUBLE_EQ(bus.bus_load(at(milliseconds(11))), 0.28);
}

TEST_F(BusTest, FrameWithoutListenerIsUnacknowledgedAndDropped) {
  for (std::uint32_t bitrate : {0u, can::kBitrate500k}) {
    SCOPED_TRACE(bitrate);
    VirtualBus bus({.bitrate = bitrate});
    const NodeHandle a = bus.attach(a_);
    const can::CanFrame f = frame(0x3C3, {1, 2});
    bus.send(a, f, at(Duration::zero()));
    bus.advance(at(seconds(1)));
    EXPECT_EQ(bus.stats().unacknowledged, 1u);
    EXPECT_EQ(bus.stats().delivered, 0u);
    EXPECT_EQ(bus.stats().transmitted, 1u);
    EXPECT_EQ(bus.frames_with_id(0x3C3), 0u);
    // It still took the wire for its length.
    EXPECT_EQ(bus.stats().busy_time, can::frame_duration(f, bitrate));
    EXPECT_EQ(bus.next_event(), kNever);
    EXPECT_EQ(a_.count(), 0u);
  }
}

TEST_F(BusTest, DetachedListenerDoesNotAcknowledge) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), l = bus.attach(listener_);
  ASSERT_TRUE(bus.detach(l).ok());
  bus.send(a, frame(0x100, {}), at(Duration::zero()));
  bus.advance(at(seconds(1)));
  EXPECT_EQ(bus.stats().unacknowledged, 1u);
  EXPECT_EQ(listener_.count(), 0u);
}

// ---------------------------------------------------------------- re-entrancy

TEST_F(BusTest, ReplyFromOnFrameIsDeliveredInTheSameAdvance) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  b_.reply = [&](const can::CanFrame& f, TimePoint t) {
    if (f.id == 0x41C) bus.sink(b).send(frame(0x41B, {0x8E}), t);
  };
  const TimePoint t = at(milliseconds(2));
  bus.send(a, frame(0x41C, {0x0E}), t);
  bus.send(a, frame(0x41C, {0x0E}), t);
  bus.advance(t);
  EXPECT_EQ(ids(a_.heard()), (std::vector<std::uint32_t>{0x41B, 0x41B}));
  EXPECT_EQ(times(a_.heard()), (std::vector<TimePoint>{t, t}));
  // Each reply was queued behind a's second request, not delivered inside it.
  EXPECT_EQ(ids(log_), (std::vector<std::uint32_t>{0x41C, 0x41C, 0x41B, 0x41B}));
  EXPECT_EQ(bus.next_event(), kNever);
}

TEST_F(BusTest, TimedReplyFollowsTheRequest) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  const can::CanFrame request = frame(0x41C, {0x0E}), response = frame(0x41B, {0x8E, 1});
  b_.reply = [&](const can::CanFrame&, TimePoint t) { bus.sink(b).send(response, t); };
  bus.send(a, request, at(Duration::zero()));
  bus.advance(at(seconds(1)));
  ASSERT_EQ(a_.count(), 1u);
  EXPECT_EQ(a_.heard()[0].rx_time, at(can::frame_duration(request, can::kBitrate500k) +
                                      can::frame_duration(response, can::kBitrate500k)));
}

TEST_F(BusTest, EndlessPingPongStopsAtTheStepLimit) {
  VirtualBus bus({.max_steps_per_advance = 100});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  a_.reply = [&](const can::CanFrame& f, TimePoint t) { bus.sink(a).send(f, t); };
  b_.reply = [&](const can::CanFrame& f, TimePoint t) { bus.sink(b).send(f, t); };
  const TimePoint t = at(milliseconds(1));
  bus.send(a, frame(0x001, {}), t);
  bus.advance(t);
  EXPECT_EQ(bus.stats().step_limit_hits, 1u);
  EXPECT_EQ(bus.stats().receptions, 100u);
  // One frame is still due; the next call carries on from there.
  EXPECT_EQ(bus.next_event(), t);
  bus.advance(t);
  EXPECT_EQ(bus.stats().step_limit_hits, 2u);
  EXPECT_EQ(bus.stats().receptions, 200u);
  EXPECT_EQ(bus.time(), t);
}

// ---------------------------------------------------------------- node control

TEST_F(BusTest, DetachedNodeNeitherSendsNorReceives) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  bus.attach(listener_);
  // b queues three frames; the first goes on the wire, then b loses power.
  bus.send(b, frame(0x101, {}), at(Duration::zero()));
  bus.send(b, frame(0x102, {}), at(Duration::zero()));
  bus.send(b, frame(0x103, {}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  ASSERT_TRUE(bus.busy());
  ASSERT_TRUE(bus.detach(b).ok());
  EXPECT_FALSE(bus.attached(b));
  EXPECT_EQ(bus.queued_frames(b), 0u);
  bus.send(b, frame(0x104, {}), at(microseconds(1)));
  bus.send(a, frame(0x200, {}), at(microseconds(1)));
  bus.advance(at(seconds(1)));
  // The cut-off frame reached nobody; a's frame did, but not b.
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x200}));
  EXPECT_EQ(b_.count(), 0u);
  EXPECT_EQ(bus.stats().aborted, 1u);
  EXPECT_EQ(bus.stats().dropped_detached, 3u);  // 0x102, 0x103 flushed; 0x104 refused
  // The aborted frame still held the bus for its length.
  const Duration d101 = can::frame_duration(frame(0x101, {}), can::kBitrate500k);
  EXPECT_EQ(listener_.heard()[0].rx_time,
            at(d101 + can::frame_duration(frame(0x200, {}), can::kBitrate500k)));

  // Power back: b sends and receives again.
  ASSERT_TRUE(bus.reattach(b).ok());
  bus.send(b, frame(0x105, {}), at(seconds(2)));
  bus.send(a, frame(0x201, {}), at(seconds(2)));
  bus.advance(at(seconds(3)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x200, 0x105, 0x201}));
  EXPECT_EQ(ids(b_.heard()), (std::vector<std::uint32_t>{0x201}));
}

TEST_F(BusTest, NodeMayPowerCycleFromItsOwnCallback) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_), c = bus.attach(c_);
  // b powers down on 0x7FF; c, served after b, must then still hear it.
  b_.reply = [&](const can::CanFrame& f, TimePoint) {
    if (f.id == 0x7FF) {
      ASSERT_TRUE(bus.detach(b).ok());
    }
  };
  bus.send(a, frame(0x7FF, {}), at(Duration::zero()));
  bus.send(a, frame(0x001, {}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  EXPECT_EQ(ids(b_.heard()), (std::vector<std::uint32_t>{0x7FF}));
  EXPECT_EQ(ids(c_.heard()), (std::vector<std::uint32_t>{0x7FF, 0x001}));
  (void)c;
}

TEST_F(BusTest, UnknownHandles) {
  VirtualBus bus;
  bus.attach(listener_);
  EXPECT_FALSE(bus.detach(NodeHandle{7}).ok());
  EXPECT_FALSE(bus.reattach(NodeHandle{7}).ok());
  bus.sink(NodeHandle{7}).send(frame(0x001, {}), at(Duration::zero()));
  bus.advance(at(seconds(1)));
  EXPECT_EQ(listener_.count(), 0u);
  EXPECT_EQ(bus.stats().dropped_detached, 1u);
}

TEST_F(BusTest, TransmitQueueCapacity) {
  VirtualBus bus({.bitrate = can::kBitrate500k, .tx_queue_capacity = 2});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  for (std::uint32_t i = 0; i < 3; ++i) bus.send(a, frame(0x100 + i, {}), at(Duration::zero()));
  EXPECT_EQ(bus.stats().queue_overflows, 1u);
  bus.advance(at(seconds(1)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x100, 0x101}));
}

// ---------------------------------------------------------------- faults

TEST_F(BusTest, DropByIdentifier) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  const RuleId rule = bus.faults().add(FaultRule::drop(0x3C3));
  bus.send(a, frame(0x3C3, {1}), at(Duration::zero()));
  bus.send(a, frame(0x3C4, {2}), at(Duration::zero()));
  bus.send(a, frame(0x3C3, {3}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x3C4}));
  EXPECT_EQ(bus.stats().fault_dropped, 2u);
  EXPECT_EQ(bus.faults().fired(rule), 2u);
  // Removing the rule lets the identifier through again.
  bus.faults().remove(rule);
  bus.send(a, frame(0x3C3, {4}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x3C4, 0x3C3}));
}

TEST_F(BusTest, DropByMaskAndSender) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  bus.attach(listener_);
  FaultRule rule;
  rule.id = 0x300;  // Group 1 message 0xC: 0x300..0x33F
  rule.mask = 0x7C0;
  rule.sender = b;
  bus.faults().add(rule);
  bus.send(a, frame(0x303, {}), at(Duration::zero()));
  bus.send(b, frame(0x305, {}), at(Duration::zero()));
  bus.send(b, frame(0x345, {}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x303, 0x345}));
}

// Sends n frames of 0x3C3 from one node through a bus with a 5 % drop rule and
// returns the indices that arrived.
std::vector<std::uint32_t> run_lossy(std::uint64_t seed, int n, double rate) {
  std::vector<Reception> log;
  RecordingPort sender("s", log), receiver("r", log);
  VirtualBus bus({.seed = seed});
  const NodeHandle s = bus.attach(sender);
  bus.attach(receiver);
  FaultRule rule = FaultRule::drop(0x3C3);
  rule.rate = rate;
  bus.faults().add(rule);
  for (int i = 0; i < n; ++i) {
    const auto v = static_cast<std::uint16_t>(i);
    bus.send(s,
             frame(0x3C3, {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)}),
             at(milliseconds(i)));
    bus.advance(at(milliseconds(i)));
  }
  std::vector<std::uint32_t> arrived;
  for (const Reception& r : log)
    arrived.push_back(r.frame.data[0] | (std::uint32_t{r.frame.data[1]} << 8));
  return arrived;
}

TEST(BusFaults, DropAtFivePercentIsDeterministic) {
  const auto first = run_lossy(42, 10000, 0.05);
  const std::size_t dropped = 10000 - first.size();
  // Binomial(10000, 0.05): mean 500, sd 21.8. With a fixed seed the count is
  // fixed; the band only says the rate is applied as configured.
  EXPECT_GE(dropped, 420u);
  EXPECT_LE(dropped, 580u);
  // Same seed, same frames lost; another seed, another pattern.
  EXPECT_EQ(run_lossy(42, 10000, 0.05), first);
  const auto other = run_lossy(43, 10000, 0.05);
  EXPECT_NE(other, first);
  EXPECT_GE(10000 - other.size(), 420u);
  EXPECT_LE(10000 - other.size(), 580u);
  // Rates 0 and 1 are exact.
  EXPECT_EQ(run_lossy(42, 100, 0.0).size(), 100u);
  EXPECT_EQ(run_lossy(42, 100, 1.0).size(), 0u);
}

TEST_F(BusTest, DelayHoldsAFrameAndLetsLaterOnesPass) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  bus.faults().add(FaultRule::delay_by(0x3C3, milliseconds(5)));
  const can::CanFrame slow = frame(0x3C3, {1}), fast = frame(0x3C4, {2});
  bus.send(a, slow, at(milliseconds(1)));
  bus.send(a, fast, at(milliseconds(1)));
  EXPECT_EQ(bus.queued_frames(a), 1u);
  bus.advance(at(seconds(1)));
  EXPECT_EQ(ids(listener_.heard()), (std::vector<std::uint32_t>{0x3C4, 0x3C3}));
  EXPECT_EQ(
      times(listener_.heard()),
      (std::vector<TimePoint>{at(milliseconds(1) + can::frame_duration(fast, can::kBitrate500k)),
                              at(milliseconds(6) + can::frame_duration(slow, can::kBitrate500k))}));
  EXPECT_EQ(bus.stats().fault_delayed, 1u);
}

TEST_F(BusTest, DelayInIdealMode) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  bus.faults().add(FaultRule::delay_by(0x100, microseconds(250)));
  bus.send(a, frame(0x100, {}), at(Duration::zero()));
  EXPECT_EQ(bus.next_event(), at(microseconds(250)));
  bus.advance(at(microseconds(249)));
  EXPECT_EQ(listener_.count(), 0u);
  bus.advance(at(microseconds(250)));
  ASSERT_EQ(listener_.count(), 1u);
  EXPECT_EQ(listener_.heard()[0].rx_time, at(microseconds(250)));
}

TEST_F(BusTest, CorruptFlipsTruncatesOrExtends) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  bus.faults().add(FaultRule::corrupt(0x001, Corruption::kFlipBits, 1));
  bus.faults().add(FaultRule::corrupt(0x002, Corruption::kFlipBits, 3));
  bus.faults().add(FaultRule::corrupt(0x003, Corruption::kTruncate, 2));
  FaultRule extend = FaultRule::corrupt(0x004, Corruption::kExtend, 3);
  extend.fill = 0xEE;
  bus.faults().add(extend);
  const can::CanFrame original = frame(0, {0x10, 0x20, 0x30, 0x40, 0x50, 0x60});
  for (std::uint32_t id = 1; id <= 4; ++id) {
    can::CanFrame f = original;
    f.id = id;
    bus.send(a, f, at(Duration::zero()));
  }
  bus.advance(at(Duration::zero()));
  const auto heard = listener_.heard();
  ASSERT_EQ(heard.size(), 4u);
  const auto differing_bits = [&](const can::CanFrame& f) {
    int n = 0;
    for (std::size_t i = 0; i < original.len; ++i)
      n += std::popcount(static_cast<unsigned>(f.data[i] ^ original.data[i]));
    return n;
  };
  EXPECT_EQ(heard[0].frame.len, 6);
  EXPECT_EQ(differing_bits(heard[0].frame), 1);
  EXPECT_EQ(heard[1].frame.len, 6);
  EXPECT_EQ(differing_bits(heard[1].frame), 3);
  EXPECT_EQ(test::hex(heard[2].frame.payload()), "10 20 30 40");
  EXPECT_EQ(test::hex(heard[3].frame.payload()), "10 20 30 40 50 60 EE EE");  // capped at 8
  EXPECT_EQ(bus.stats().fault_corrupted, 4u);
}

TEST_F(BusTest, CorruptSkipsFramesItCannotChange) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  FaultRule rule = FaultRule::corrupt(0x001, Corruption::kFlipBits);
  rule.count = 1;
  const RuleId id = bus.faults().add(rule);
  bus.send(a, frame(0x001, {}), at(Duration::zero()));      // nothing to flip
  bus.send(a, frame(0x001, {0x00}), at(Duration::zero()));  // this one
  bus.send(a, frame(0x001, {0x00}), at(Duration::zero()));  // rule spent
  bus.advance(at(Duration::zero()));
  const auto heard = listener_.heard();
  ASSERT_EQ(heard.size(), 3u);
  EXPECT_EQ(heard[0].frame.len, 0);
  EXPECT_EQ(std::popcount(static_cast<unsigned>(heard[1].frame.data[0])), 1);
  EXPECT_EQ(heard[2].frame.data[0], 0x00);
  EXPECT_EQ(bus.faults().fired(id), 1u);
}

TEST_F(BusTest, NextNMatchingFrames) {
  VirtualBus bus;
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  FaultRule rule = FaultRule::drop(0x41B);
  rule.count = 3;
  const RuleId id = bus.faults().add(rule);
  EXPECT_EQ(bus.faults().remaining(id), 3u);
  for (std::uint8_t i = 0; i < 6; ++i) {
    bus.send(a, frame(0x41B, {i}), at(Duration::zero()));
    bus.send(a, frame(0x41C, {i}), at(Duration::zero()));  // never matches
  }
  bus.advance(at(Duration::zero()));
  std::vector<std::uint8_t> got;
  for (const Reception& r : listener_.heard()) {
    if (r.frame.id == 0x41B) got.push_back(r.frame.data[0]);
  }
  EXPECT_EQ(got, (std::vector<std::uint8_t>{3, 4, 5}));
  EXPECT_EQ(listener_.count(), 9u);
  EXPECT_EQ(bus.faults().remaining(id), 0u);
  EXPECT_FALSE(bus.faults().active(id));
  EXPECT_EQ(bus.faults().matched(id), 3u);
}

// A busy scene: three nodes, random traffic, every kind of fault at a rate.
std::vector<Reception> run_scene(std::uint64_t seed) {
  std::vector<Reception> log;
  RecordingPort p0("0", log), p1("1", log), p2("2", log);
  VirtualBus bus({.bitrate = can::kBitrate250k, .seed = seed});
  const std::array<NodeHandle, 3> nodes{bus.attach(p0), bus.attach(p1), bus.attach(p2)};
  FaultRule drop;
  drop.rate = 0.05;
  FaultRule delay;
  delay.action = FaultAction::kDelay;
  delay.delay = microseconds(700);
  delay.rate = 0.05;
  FaultRule corrupt;
  corrupt.action = FaultAction::kCorrupt;
  corrupt.amount = 2;
  corrupt.rate = 0.05;
  bus.faults().add(drop);
  bus.faults().add(delay);
  bus.faults().add(corrupt);
  std::mt19937_64 traffic(7);  // the traffic is the same for every seed
  TimePoint t{};
  for (int i = 0; i < 2000; ++i) {
    t += microseconds(static_cast<std::int64_t>(traffic() % 400));
    bus.advance(t);
    can::CanFrame f;
    f.id = static_cast<std::uint32_t>(traffic() & can::kMaxStandardId);
    f.len = static_cast<std::uint8_t>(traffic() % 9);
    for (std::size_t k = 0; k < f.len; ++k) f.data[k] = static_cast<std::uint8_t>(traffic());
    bus.send(nodes[traffic() % 3], f, t);
  }
  bus.advance(kNever - seconds(1));
  EXPECT_EQ(bus.next_event(), kNever);
  EXPECT_GT(bus.stats().fault_dropped, 0u);
  EXPECT_GT(bus.stats().fault_delayed, 0u);
  EXPECT_GT(bus.stats().fault_corrupted, 0u);
  return log;
}

TEST(BusFaults, SameSeedSameRun) {
  const auto first = run_scene(1234);
  EXPECT_GT(first.size(), 3000u);
  EXPECT_EQ(run_scene(1234), first);
  EXPECT_NE(run_scene(4321), first);
}

// ---------------------------------------------------------------- tap

TEST_F(BusTest, TapSeesEveryCompletedFrameInWireOrderBeforeTheReceivers) {
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_), b = bus.attach(b_);
  bus.attach(listener_);
  std::vector<WireFrame> tapped;
  std::vector<std::size_t> heard_when_tapped;
  bus.set_tap([&](const WireFrame& f) {
    tapped.push_back(f);
    heard_when_tapped.push_back(listener_.count());
  });
  const can::CanFrame fa = frame(0x300, {1, 2}), fb = frame(0x100, {3});
  const TimePoint t0 = at(milliseconds(1));
  bus.send(a, fa, t0);
  bus.send(b, fb, t0);
  bus.advance(at(seconds(1)));

  ASSERT_EQ(tapped.size(), 2u);
  // Arbitration order, each stamped with its end of frame and its sender.
  EXPECT_EQ(tapped[0].frame, fb);
  EXPECT_EQ(tapped[0].sender, b);
  EXPECT_EQ(tapped[0].end, t0 + can::frame_duration(fb, can::kBitrate500k));
  EXPECT_TRUE(tapped[0].acknowledged);
  EXPECT_EQ(tapped[1].frame, fa);
  EXPECT_EQ(tapped[1].sender, a);
  EXPECT_EQ(tapped[1].end, tapped[0].end + can::frame_duration(fa, can::kBitrate500k));
  // The same times the receivers are given, and before they are given them.
  EXPECT_EQ(times(listener_.heard()), (std::vector<TimePoint>{tapped[0].end, tapped[1].end}));
  EXPECT_EQ(heard_when_tapped, (std::vector<std::size_t>{0, 1}));

  // An empty tap removes it.
  bus.set_tap({});
  bus.send(a, fa, at(seconds(2)));
  bus.advance(at(seconds(3)));
  EXPECT_EQ(tapped.size(), 2u);
  EXPECT_EQ(listener_.count(), 3u);
}

TEST_F(BusTest, TapSeesUnacknowledgedFramesButNotAbortedOnes) {
  for (std::uint32_t bitrate : {0u, can::kBitrate500k}) {
    SCOPED_TRACE(bitrate);
    VirtualBus bus({.bitrate = bitrate});
    const NodeHandle a = bus.attach(a_);
    std::vector<WireFrame> tapped;
    bus.set_tap([&](const WireFrame& f) { tapped.push_back(f); });
    // Alone on the bus: nobody acknowledges, an analyser still sees it.
    bus.send(a, frame(0x407, {0, 59, 0, 1, 0, 0, 0xDB}), at(milliseconds(1)));
    bus.advance(at(seconds(1)));
    ASSERT_EQ(tapped.size(), 1u);
    EXPECT_FALSE(tapped[0].acknowledged);
    EXPECT_EQ(tapped[0].end, at(milliseconds(1)) + can::frame_duration(tapped[0].frame, bitrate));
    EXPECT_EQ(bus.stats().unacknowledged, 1u);
  }
  // Cut off mid-way: never completed, not seen.
  VirtualBus bus({.bitrate = can::kBitrate500k});
  const NodeHandle a = bus.attach(a_);
  bus.attach(listener_);
  std::vector<WireFrame> tapped;
  bus.set_tap([&](const WireFrame& f) { tapped.push_back(f); });
  bus.send(a, frame(0x101, {}), at(Duration::zero()));
  bus.advance(at(Duration::zero()));
  ASSERT_TRUE(bus.busy());
  ASSERT_TRUE(bus.detach(a).ok());
  bus.advance(at(seconds(1)));
  EXPECT_EQ(bus.stats().aborted, 1u);
  EXPECT_TRUE(tapped.empty());
}

}  // namespace
}  // namespace dnbridge::sim
