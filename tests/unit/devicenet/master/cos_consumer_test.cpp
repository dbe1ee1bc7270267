// The master's end of a change-of-state connection, on a test clock: each
// message acknowledged (unless suppressed) on Group 2 message 2; the
// device's retries of an unacknowledged message seen as repeats; 4 × EPR
// without a message is the connection's loss, once, until a message again.
#include "bridge/devicenet/master/cos_consumer.hpp"

#include <gtest/gtest.h>

#include <array>

namespace dnbridge::devicenet {
namespace {

const TimePoint t0 = TimePoint{} + seconds(10);
const MacId kSlave = MacId::from_bits(12);

Bytes bytes(const std::array<std::uint8_t, 2>& a) { return Bytes(a.data(), a.size()); }

CosSettings settings() {
  CosSettings s;
  s.expected_packet_rate = milliseconds(100);
  return s;  // ack timer 20 ms, retry limit 1: the Acknowledge Handler's defaults
}

TEST(CosConsumer, EachMessageIsAcknowledgedOnGroup2Message2) {
  CosConsumer c(kSlave, settings(), t0);
  const std::array<std::uint8_t, 2> a{0x01, 0x00};
  const auto taken = c.on_message(bytes(a), t0 + milliseconds(3));
  EXPECT_TRUE(taken.acknowledge);
  EXPECT_FALSE(taken.repeat);
  const can::CanFrame ack = c.ack_frame();
  EXPECT_EQ(ack.id, 0x400u | (12u << 3) | 2u);  // 0x462
  EXPECT_EQ(ack.len, 0);
  EXPECT_EQ(c.counters().acks_sent, 1u);
}

TEST(CosConsumer, WithAcknowledgmentSuppressedNothingIsAcknowledged) {
  CosSettings s = settings();
  s.ack_suppressed = true;
  CosConsumer c(kSlave, s, t0);
  const std::array<std::uint8_t, 2> a{0x01, 0x00};
  EXPECT_FALSE(c.on_message(bytes(a), t0).acknowledge);
  // Nothing is retried without acknowledgment: the same data soon is no repeat.
  EXPECT_FALSE(c.on_message(bytes(a), t0 + milliseconds(15)).repeat);
  EXPECT_EQ(c.counters().acks_sent, 0u);
  EXPECT_EQ(c.counters().messages, 2u);
}

TEST(CosConsumer, TheSameDataWithinTheAckTimerIsTheDevicesRetry) {
  CosConsumer c(kSlave, settings(), t0);
  const std::array<std::uint8_t, 2> a{0x05, 0x00};
  const std::array<std::uint8_t, 2> b{0x07, 0x00};
  c.on_message(bytes(a), t0);
  // The ack was lost: the device sends it again at its acknowledge timer.
  auto again = c.on_message(bytes(a), t0 + milliseconds(21));
  EXPECT_TRUE(again.repeat);
  EXPECT_TRUE(again.acknowledge);  // a retry wants its ack as much
  // Its retry limit is 1: the same data once more is not a retry of it.
  EXPECT_FALSE(c.on_message(bytes(a), t0 + milliseconds(42)).repeat);
  // A change is never a repeat; a heartbeat an EPR later is not either.
  EXPECT_FALSE(c.on_message(bytes(b), t0 + milliseconds(50)).repeat);
  EXPECT_FALSE(c.on_message(bytes(b), t0 + milliseconds(150)).repeat);
  EXPECT_EQ(c.counters().repeats, 1u);
  EXPECT_EQ(c.counters().messages, 5u);
}

TEST(CosConsumer, FourExpectedPacketRatesWithoutAMessageIsALossOnceUntilAMessage) {
  CosConsumer c(kSlave, settings(), t0);
  EXPECT_EQ(c.watchdog_deadline(), t0 + milliseconds(400));
  EXPECT_FALSE(c.check_watchdog(t0 + milliseconds(399)));
  const std::array<std::uint8_t, 2> a{0x01, 0x00};
  c.on_message(bytes(a), t0 + milliseconds(300));  // a heartbeat in time
  EXPECT_EQ(c.watchdog_deadline(), t0 + milliseconds(700));
  EXPECT_FALSE(c.check_watchdog(t0 + milliseconds(699)));
  EXPECT_TRUE(c.check_watchdog(t0 + milliseconds(700)));
  EXPECT_TRUE(c.lost());
  EXPECT_FALSE(c.check_watchdog(t0 + milliseconds(2000)));  // said once
  EXPECT_EQ(c.counters().losses, 1u);
  c.on_message(bytes(a), t0 + milliseconds(2100));
  EXPECT_FALSE(c.lost());
  EXPECT_TRUE(c.check_watchdog(t0 + milliseconds(2500)));
  EXPECT_EQ(c.counters().losses, 2u);
}

}  // namespace
}  // namespace dnbridge::devicenet
