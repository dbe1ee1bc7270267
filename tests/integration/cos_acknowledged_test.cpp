// A change-of-state connection with acknowledgment, device and master ends
// face to face on a test clock (the frames between them are the producer's
// messages and the consumer's acknowledgments): the device produces on a
// change, no sooner than its inhibit time, and as a heartbeat every EPR; an
// acknowledgment withheld makes it send the message again at its
// acknowledge timer, up to its retry limit, and the master counts each
// retry (an acknowledgment when none waits is counted late); a cyclic device
// produces every EPR only; a device that stops
// producing is lost after 4 × EPR.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <vector>

#include "adapters/sim/generic/cos_producer.hpp"
#include "bridge/devicenet/master/cos_consumer.hpp"

namespace dnbridge {
namespace {

const TimePoint t0 = TimePoint{} + seconds(20);

class CosLink {
 public:
  CosLink(sim::CosProduction production, devicenet::CosSettings consumption)
      : producer_(production, Bytes(initial_.data(), initial_.size()), t0),
        consumer_(devicenet::MacId::from_bits(9), consumption, t0) {}

  // Runs the device's timers and delivers what it sends, up to `until`.
  void run_until(TimePoint until) {
    for (;;) {
      const TimePoint next = producer_.next_deadline();
      if (next > until) break;
      now_ = next;
      deliver(producer_.on_timer(now_));
    }
    now_ = until;
  }
  void set_data(std::vector<std::uint8_t> data) {
    deliver(producer_.set_data(Bytes(data.data(), data.size()), now_));
  }
  // Acknowledgments the master sends are lost while this holds.
  bool drop_acks = false;

  sim::CosProducer& producer() { return producer_; }
  devicenet::CosConsumer& consumer() { return consumer_; }
  std::vector<TimePoint> sent_at;

 private:
  void deliver(const std::optional<std::vector<std::uint8_t>>& message) {
    if (!message) return;
    sent_at.push_back(now_);
    const auto taken = consumer_.on_message(Bytes(message->data(), message->size()), now_);
    if (taken.acknowledge && !drop_acks) producer_.on_ack();
  }

  std::array<std::uint8_t, 2> initial_{0, 0};
  TimePoint now_ = t0;
  sim::CosProducer producer_;
  devicenet::CosConsumer consumer_;
};

sim::CosProduction production() {
  sim::CosProduction p;
  p.expected_packet_rate = milliseconds(200);
  p.inhibit = milliseconds(10);
  return p;
}

devicenet::CosSettings consumption() {
  devicenet::CosSettings s;
  s.expected_packet_rate = milliseconds(200);
  return s;
}

TEST(CosAcknowledged, ChangesAndHeartbeatsAreAcknowledgedAndNeverRepeated) {
  CosLink link(production(), consumption());
  link.run_until(t0 + milliseconds(50));
  link.set_data({1, 0});
  link.run_until(t0 + milliseconds(55));
  link.set_data({2, 0});  // within the inhibit time: held back until 60 ms
  link.run_until(t0 + milliseconds(1000));
  ASSERT_GE(link.sent_at.size(), 3u);
  EXPECT_EQ(link.sent_at[0], t0 + milliseconds(50));
  EXPECT_EQ(link.sent_at[1], t0 + milliseconds(60));
  EXPECT_EQ(link.sent_at[2], t0 + milliseconds(260));  // a heartbeat, an EPR later
  EXPECT_EQ(link.producer().counters().retries, 0u);
  EXPECT_EQ(link.producer().counters().acks_received, link.sent_at.size());
  EXPECT_EQ(link.consumer().counters().repeats, 0u);
  EXPECT_EQ(link.consumer().last_data(), (std::vector<std::uint8_t>{2, 0}));
  EXPECT_FALSE(link.consumer().check_watchdog(t0 + milliseconds(1000)));
}

TEST(CosAcknowledged, AWithheldAckIsRetriedAtTheAckTimerUpToTheLimitAndCounted) {
  sim::CosProduction p = production();
  p.retry_limit = 2;
  devicenet::CosSettings s = consumption();
  s.retry_limit = 2;
  CosLink link(p, s);
  link.drop_acks = true;
  link.run_until(t0 + milliseconds(20));
  link.set_data({7, 0});
  link.run_until(t0 + milliseconds(150));
  // The message at 20 ms, then twice again, 20 ms apart; then the device
  // gives it up.
  ASSERT_EQ(link.sent_at.size(), 3u);
  EXPECT_EQ(link.sent_at[0], t0 + milliseconds(20));
  EXPECT_EQ(link.sent_at[1], t0 + milliseconds(40));
  EXPECT_EQ(link.sent_at[2], t0 + milliseconds(60));
  EXPECT_EQ(link.producer().counters().retries, 2u);
  EXPECT_EQ(link.producer().counters().given_up, 1u);
  EXPECT_EQ(link.consumer().counters().repeats, 2u);
  EXPECT_EQ(link.consumer().counters().acks_sent, 3u);
  // Acknowledged again: no more retries.
  link.drop_acks = false;
  link.set_data({8, 0});
  link.run_until(t0 + milliseconds(200));
  EXPECT_EQ(link.producer().counters().retries, 2u);
  EXPECT_EQ(link.consumer().counters().repeats, 2u);
}

// An acknowledgment that comes when no message waits (after the device gave
// its message up) is too late: counted as such, not as one received; the
// next message's counts as ever.
TEST(CosAcknowledged, AnAcknowledgmentAfterTheRetriesIsCountedLate) {
  CosLink link(production(), consumption());
  link.drop_acks = true;
  link.run_until(t0 + milliseconds(20));
  link.set_data({7, 0});
  link.run_until(t0 + milliseconds(100));
  ASSERT_EQ(link.producer().counters().given_up, 1u);
  link.producer().on_ack();
  link.producer().on_ack();  // the retry's
  EXPECT_EQ(link.producer().counters().late_acks, 2u);
  EXPECT_EQ(link.producer().counters().acks_received, 0u);
  link.drop_acks = false;
  link.set_data({8, 0});
  EXPECT_EQ(link.producer().counters().acks_received, 1u);
  EXPECT_EQ(link.producer().counters().late_acks, 2u);
}

TEST(CosAcknowledged, WithAcknowledgmentSuppressedNothingIsRetried) {
  sim::CosProduction p = production();
  p.ack_suppressed = true;
  devicenet::CosSettings s = consumption();
  s.ack_suppressed = true;
  CosLink link(p, s);
  link.drop_acks = true;
  link.set_data({3, 0});
  link.run_until(t0 + milliseconds(150));
  EXPECT_EQ(link.sent_at.size(), 1u);
  EXPECT_EQ(link.producer().counters().retries, 0u);
  EXPECT_EQ(link.consumer().counters().acks_sent, 0u);
}

TEST(CosAcknowledged, ACyclicDeviceProducesEveryEprOnly) {
  sim::CosProduction p = production();
  p.cyclic = true;
  CosLink link(p, consumption());
  link.set_data({4, 0});  // no message of its own
  link.run_until(t0 + milliseconds(650));
  ASSERT_EQ(link.sent_at.size(), 3u);
  EXPECT_EQ(link.sent_at[0], t0 + milliseconds(200));
  EXPECT_EQ(link.sent_at[1], t0 + milliseconds(400));
  EXPECT_EQ(link.sent_at[2], t0 + milliseconds(600));
  EXPECT_EQ(link.consumer().counters().repeats, 0u);
  EXPECT_EQ(link.consumer().last_data(), (std::vector<std::uint8_t>{4, 0}));
}

TEST(CosAcknowledged, ADeviceThatFallsSilentIsLostAfterFourEprs) {
  CosLink link(production(), consumption());
  link.run_until(t0 + milliseconds(450));  // heartbeats at 200 and 400 ms
  EXPECT_EQ(link.sent_at.size(), 2u);
  // The device stops (powered off): nothing more is run.
  EXPECT_FALSE(link.consumer().check_watchdog(t0 + milliseconds(1199)));
  EXPECT_TRUE(link.consumer().check_watchdog(t0 + milliseconds(1200)));
  EXPECT_EQ(link.consumer().counters().losses, 1u);
}

TEST(CosAcknowledged, ARetryResendsTheMessageAwaitedNotAChangeHeldBack) {
  sim::CosProduction p = production();
  p.inhibit = milliseconds(30);
  CosLink link(p, consumption());
  link.drop_acks = true;
  link.run_until(t0 + milliseconds(30));
  link.set_data({1, 0});  // sent at 30 ms
  link.run_until(t0 + milliseconds(35));
  link.set_data({2, 0});  // held back by the inhibit time until 60 ms
  link.run_until(t0 + milliseconds(55));
  // The retry at 50 ms is the message awaited, {1, 0}: the master sees a repeat.
  ASSERT_EQ(link.sent_at.size(), 2u);
  EXPECT_EQ(link.sent_at[1], t0 + milliseconds(50));
  EXPECT_EQ(link.consumer().last_data(), (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(link.consumer().counters().repeats, 1u);
  link.run_until(t0 + milliseconds(61));
  ASSERT_EQ(link.sent_at.size(), 3u);
  EXPECT_EQ(link.sent_at[2], t0 + milliseconds(60));
  EXPECT_EQ(link.consumer().last_data(), (std::vector<std::uint8_t>{2, 0}));
  EXPECT_EQ(link.consumer().counters().repeats, 1u);
}

TEST(CosAcknowledged, CyclesFasterThanTheAckTimerAreNeverTakenForRetries) {
  sim::CosProduction p = production();
  p.cyclic = true;
  p.expected_packet_rate = milliseconds(10);
  devicenet::CosSettings s = consumption();
  s.expected_packet_rate = milliseconds(10);
  CosLink link(p, s);
  link.drop_acks = true;
  link.run_until(t0 + milliseconds(105));
  EXPECT_EQ(link.sent_at.size(), 10u);
  EXPECT_EQ(link.producer().counters().retries, 0u);  // each cycle supersedes the wait
  EXPECT_EQ(link.consumer().counters().repeats, 0u);
}

TEST(CosAcknowledged, AnEprOfZeroMeansNoHeartbeatAndNoWatchdog) {
  sim::CosProduction p = production();
  p.expected_packet_rate = Duration::zero();
  devicenet::CosSettings s = consumption();
  s.expected_packet_rate = Duration::zero();
  CosLink link(p, s);
  link.run_until(t0 + seconds(5));
  EXPECT_TRUE(link.sent_at.empty());
  link.set_data({5, 0});
  link.run_until(t0 + seconds(10));
  EXPECT_EQ(link.sent_at.size(), 1u);
  EXPECT_FALSE(link.consumer().check_watchdog(t0 + seconds(3600)));
}

TEST(CosAcknowledged, AHeartbeatSoonAfterARetryIsNoRepeatAndAZeroAckTimerIsOneMs) {
  sim::CosProduction p = production();
  p.expected_packet_rate = milliseconds(30);
  p.retry_limit = 2;
  devicenet::CosSettings s = consumption();
  s.expected_packet_rate = milliseconds(30);
  s.retry_limit = 2;
  CosLink link(p, s);
  link.drop_acks = true;
  // Heartbeats at 30 ms apart; the first one's retry at 50 ms, then the
  // heartbeat at 60 ms, 10 ms after that retry: not a repeat.
  link.run_until(t0 + milliseconds(65));
  ASSERT_EQ(link.sent_at.size(), 3u);
  EXPECT_EQ(link.sent_at[1], t0 + milliseconds(50));
  EXPECT_EQ(link.sent_at[2], t0 + milliseconds(60));
  EXPECT_EQ(link.consumer().counters().repeats, 1u);

  sim::CosProduction zero = production();
  zero.ack_timer = Duration::zero();
  CosLink fast(zero, consumption());
  fast.drop_acks = true;
  fast.run_until(t0 + milliseconds(20));
  fast.set_data({1, 0});
  fast.run_until(t0 + milliseconds(25));
  ASSERT_EQ(fast.sent_at.size(), 2u);
  EXPECT_EQ(fast.sent_at[1], t0 + milliseconds(21));
}

}  // namespace
}  // namespace dnbridge
