// The simulated CDN127 on the wire, frame by frame with a fake clock
// (cdn127_slave_fixture.hpp): what a power cycle and an Identity reset keep
// and what they drop (E2, output actions, faults, connections).
#include <gtest/gtest.h>

#include <cstdint>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "sim/cdn127/cdn127_slave_fixture.hpp"

namespace dnbridge::sim {
namespace {

// ---------------------------------------------------------------------------
// Resets and power cycles

TEST_F(Cdn127SlaveTest, PowerCycleKeepsE2AndDropsEverythingElse) {
  boot();
  allocate();
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));    // CDN118 preset
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0x00, 0x02}), (ByteVec{0x90}));  // AOP fault value
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x01});
  ASSERT_TRUE(slave_->outputs().pump_on);

  slave_->power_cycle(now_);
  auto out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, kDupMacId);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->outputs(), profiles::cdn127::PumpOutputs{});
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kPowerUp);
  advance(milliseconds(2001));
  allocate();
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0B), (ByteVec{0x8E, 0x00, 0x02}));
  EXPECT_EQ(get(0x05, 0x02, 0x09), (ByteVec{0x8E, 0x00, 0x00}));
}

// The fault and idle actions a master writes are E2: a power cycle keeps
// them and they act after it, while the outputs start off.
TEST_F(Cdn127SlaveTest, PowerCycleKeepsTheOutputActionsWrittenAndStartsWithOutputsOff) {
  create(unsafe_options());
  boot();
  allocate();
  for (std::uint8_t instance : kDopInstances) {
    EXPECT_EQ(set(0x09, instance, 0x05, {0x00}), (ByteVec{0x90}));  // fault: the value,
    EXPECT_EQ(set(0x09, instance, 0x07, {0x00}), (ByteVec{0x90}));  // idle: the value,
    EXPECT_EQ(set(0x09, instance, 0x08, {0x00}), (ByteVec{0x90}));  // Off
  }
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x03}), (ByteVec{0x90}));        // fault: the value,
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0xC8, 0x00}), (ByteVec{0x90}));  // 200
  EXPECT_EQ(set(0x0B, 0x01, 0x0A, {0x01}), (ByteVec{0x90}));        // idle: low
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x34, 0x02});
  ASSERT_TRUE(slave_->outputs().pump_on);

  slave_->power_cycle(now_);
  auto out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, kDupMacId);
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kDuplicateMacCheck);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->outputs(), profiles::cdn127::PumpOutputs{});
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kPowerUp);
  // Silent to a master until the check is over.
  EXPECT_TRUE(exchange(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster}).empty());
  advance(milliseconds(2001));
  ASSERT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);

  allocate();
  for (std::uint8_t instance : kDopInstances) {
    EXPECT_EQ(get(0x09, instance, 0x05), (ByteVec{0x8E, 0x00}));
    EXPECT_EQ(get(0x09, instance, 0x07), (ByteVec{0x8E, 0x00}));
    EXPECT_EQ(get(0x09, instance, 0x08), (ByteVec{0x8E, 0x00}));
  }
  EXPECT_EQ(get(0x0B, 0x01, 0x09), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0B), (ByteVec{0x8E, 0xC8, 0x00}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x01}));
  // And they act: idle, then a timeout.
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x34, 0x02});
  poll({});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0);
  poll({0x05, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 200);
}

// A power cycle is the exit from an unrecoverable fault (manual, Identity
// attribute 8); a recoverable one stands, its cause being outside the
// device. An Identity Reset is no power cycle.
TEST_F(Cdn127SlaveTest, PowerCycleEndsUnrecoverableFaultsOnly) {
  boot();
  const IdentityFaults all{.minor_recoverable = true,
                           .minor_unrecoverable = true,
                           .major_recoverable = true,
                           .major_unrecoverable = true};
  slave_->device().set_faults(all, now_);
  allocate();
  exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01});  // Identity Reset
  advance(milliseconds(2001));
  EXPECT_EQ(slave_->device().faults(), all);

  slave_->power_cycle(now_);
  advance(milliseconds(2001));
  EXPECT_EQ(slave_->device().faults(),
            (IdentityFaults{.minor_recoverable = true, .major_recoverable = true}));
  EXPECT_EQ(slave_->outputs(), profiles::cdn127::PumpOutputs{});
  allocate();
  EXPECT_EQ(get(0x01, 0x01, 0x05), (ByteVec{0x8E, 0x01, 0x05}));
  EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, 0x04}));
}

TEST_F(Cdn127SlaveTest, IdentityResetRestartsAfterAnswering) {
  boot();
  allocate();
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  auto out = exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 85");
  EXPECT_EQ(out[1].id, kDupMacId);
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kDuplicateMacCheck);
  advance(milliseconds(2001));
  allocate();
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));  // type 0 keeps E2
  // Type 1: out-of-box settings
  exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01, 0x01});
  advance(milliseconds(2001));
  allocate();
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x86}));
  EXPECT_EQ(request({0x05, 0x01, 0x01, 0x02}), error(0x20));
  EXPECT_EQ(request({0x05, 0x01, 0x00}), error(0x08));
}

}  // namespace
}  // namespace dnbridge::sim
