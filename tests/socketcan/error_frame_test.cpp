// SocketCAN error frames as bus state: golden frames laid out as
// linux/can/error.h defines them (class bits in the identifier, details in
// the data bytes).
#include "adapters/socketcan/error_frame.hpp"

#include <gtest/gtest.h>
#include <linux/can/error.h>

namespace dnbridge::socketcan {
namespace {

using port::BusState;
using Data = std::array<std::uint8_t, 8>;

TEST(ErrorFrame, ControllerWarningWithCounters) {
  // class CRTL | CNT; data[1] = TX warning; data[6] = tx errors 96, data[7] = rx errors 3
  const Data d{0, CAN_ERR_CRTL_TX_WARNING, 0, 0, 0, 0, 96, 3};
  const auto r = decode_error_frame(CAN_ERR_CRTL | CAN_ERR_CNT, d);
  EXPECT_EQ(r.state, BusState::kErrorWarning);
  EXPECT_EQ(r.tx_errors, 96);
  EXPECT_EQ(r.rx_errors, 3);
  EXPECT_FALSE(r.bus_off);
}

TEST(ErrorFrame, PassiveWinsOverWarningInOneFrame) {
  // data[1] = RX warning | TX passive
  const Data d{0, CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 128, 100};
  EXPECT_EQ(decode_error_frame(CAN_ERR_CRTL, d).state, BusState::kErrorPassive);
}

TEST(ErrorFrame, BackToErrorActive) {
  const Data d{0, CAN_ERR_CRTL_ACTIVE, 0, 0, 0, 0, 10, 0};
  EXPECT_EQ(decode_error_frame(CAN_ERR_CRTL, d).state, BusState::kErrorActive);
}

TEST(ErrorFrame, BusOffAndRestart) {
  const Data none{};
  const auto off = decode_error_frame(CAN_ERR_BUSOFF, none);
  EXPECT_TRUE(off.bus_off);
  EXPECT_EQ(off.state, BusState::kBusOff);
  EXPECT_FALSE(off.tx_errors.has_value()) << "no counters without CRTL or CNT";
  const auto restarted = decode_error_frame(CAN_ERR_RESTARTED, none);
  EXPECT_TRUE(restarted.restarted);
  EXPECT_EQ(restarted.state, BusState::kErrorActive);
  EXPECT_EQ(describe(off), "bus-off");
}

TEST(ErrorFrame, EventsWithoutAStateLeaveItAlone) {
  const Data none{};
  const auto r = decode_error_frame(CAN_ERR_ACK | CAN_ERR_PROT | CAN_ERR_TX_TIMEOUT, none);
  EXPECT_FALSE(r.state.has_value());
  EXPECT_TRUE(r.no_ack);
  EXPECT_TRUE(r.protocol);
  EXPECT_TRUE(r.tx_timeout);
  EXPECT_EQ(describe(r), "no ACK, transmit timeout, protocol violation");
}

TEST(ErrorFrame, ControllerOverflowsAreReported) {
  const Data d{0, CAN_ERR_CRTL_RX_OVERFLOW, 0, 0, 0, 0, 0, 0};
  const auto r = decode_error_frame(CAN_ERR_CRTL, d);
  EXPECT_TRUE(r.rx_overflow);
  EXPECT_FALSE(r.state.has_value());
}

TEST(ErrorFrame, GarbageNeverClaimsAState) {
  // Unknown class bits and arbitrary bytes: no state, no crash.
  const Data d{0xFF, 0x80, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  const auto r = decode_error_frame(0x1FFF0000u, d);
  EXPECT_FALSE(r.state.has_value());
  EXPECT_EQ(describe(r), "unclassified error frame");
}

}  // namespace
}  // namespace dnbridge::socketcan
