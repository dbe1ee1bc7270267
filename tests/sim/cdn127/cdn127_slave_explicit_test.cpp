// The simulated CDN127 on the wire, frame by frame with a fake clock
// (cdn127_slave_fixture.hpp): the duplicate MAC check at power-up and when
// online, Allocate and Release on the unconnected port, the Identity object
// and explicit messaging with its fragmentation.
#include <gtest/gtest.h>

#include <cstdint>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "sim/cdn127/cdn127_slave_fixture.hpp"

namespace dnbridge::sim {
namespace {

// ---------------------------------------------------------------------------
// Duplicate MAC ID check (bridge/PROTOCOL.md §6)

TEST_F(Cdn127SlaveTest, PowerUpSendsTwoDuplicateMacRequestsThenGoesOnline) {
  slave_->power_on(now_);
  auto first = sink_.take();
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].id, kDupMacId);
  // request, port 0 | vendor 59 LE | serial 0x00001234 LE
  EXPECT_EQ(bytes_of(first[0]), (ByteVec{0x00, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}));
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kDuplicateMacCheck);

  // Nothing but the check before going online: an Allocate goes unanswered.
  EXPECT_TRUE(exchange(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster}).empty());

  advance(milliseconds(1000));
  auto second = sink_.take();
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0], first[0]);
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kDuplicateMacCheck);

  advance(milliseconds(1000));
  EXPECT_TRUE(sink_.take().empty());
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
  allocate();
}

TEST_F(Cdn127SlaveTest, DuplicateDuringCheckIsCommunicationFaultAndSilence) {
  slave_->power_on(now_);
  sink_.take();
  advance(milliseconds(500));
  // Another node checking MAC 3 (vendor 1, serial 99).
  EXPECT_TRUE(exchange(kDupMacId, {0x00, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kCommunicationFault);
  advance(seconds(5));
  EXPECT_TRUE(sink_.take().empty());
  EXPECT_TRUE(exchange(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster}).empty());
  EXPECT_TRUE(exchange(kDupMacId, {0x00, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}).empty());
  EXPECT_GT(slave_->counters().frames_ignored, 0u);

  // A power cycle runs the check again.
  slave_->power_cycle(now_);
  EXPECT_EQ(sink_.take().size(), 1u);
  advance(milliseconds(2001));
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
}

TEST_F(Cdn127SlaveTest, OnlineDefendsItsMacAndFaultsOnAResponse) {
  boot();
  allocate();
  // A request for MAC 3 is answered with a response (R/R bit set).
  EXPECT_EQ(single(kDupMacId, {0x00, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}, kDupMacId),
            (ByteVec{0x80, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}));
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
  // A response from another node with MAC 3: duplicate, connections dropped.
  EXPECT_TRUE(exchange(kDupMacId, {0x80, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kCommunicationFault);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x01}).empty());
}

TEST_F(Cdn127SlaveTest, IgnoresOtherNodesDuplicateMacChecks) {
  boot();
  EXPECT_TRUE(exchange(0x457, {0x00, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}).empty());  // MAC 10
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
  EXPECT_EQ(slave_->counters().frames_not_addressed, 1u);
}

// ---------------------------------------------------------------------------
// Allocation (bridge/PROTOCOL.md §3)

TEST_F(Cdn127SlaveTest, AllocateExplicitAndPoll) {
  boot();
  // [M=10][Allocate][class 3][instance 1][choice explicit|poll][allocator 10]
  // -> [M=10][Allocate response][body format 0 = 8/8]
  EXPECT_EQ(single(kUnconnectedId, {0x0A, 0x4B, 0x03, 0x01, 0x03, 0x0A}),
            (ByteVec{0x0A, 0xCB, 0x00}));
  EXPECT_EQ(slave_->owner(), kMaster);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kEstablished);
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kConfiguring);
  // Allocation information {choice, master MAC}; Identity status owned bit.
  EXPECT_EQ(get(0x03, 0x01, 0x05), (ByteVec{0x8E, 0x03, 0x0A}));
  EXPECT_EQ(get(0x01, 0x01, 0x05), (ByteVec{0x8E, 0x01, 0x00}));
}

TEST_F(Cdn127SlaveTest, AllocateErrors) {
  boot();
  // choice 0: invalid attribute value / invalid choice
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x00, kMaster}),
            (ByteVec{kMaster, 0x94, 0x09, 0x02}));
  // bit strobe: resource unavailable / invalid choice
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x05, kMaster}),
            (ByteVec{kMaster, 0x94, 0x02, 0x02}));
  // COS, cyclic, ack suppression likewise
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x51, kMaster}),
            (ByteVec{kMaster, 0x94, 0x02, 0x02}));
  // poll alone with no explicit connection
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x02, kMaster}),
            (ByteVec{kMaster, 0x94, 0x09, 0x02}));
  EXPECT_EQ(slave_->owner(), 255);

  allocate(0x01);
  // explicit again: already allocated
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x01, kMaster}),
            (ByteVec{kMaster, 0x94, 0x0B, 0x02}));
  // another master (11): owned, allocation conflict
  EXPECT_EQ(single(kUnconnectedId, {0x0B, 0x4B, 0x03, 0x01, 0x03, 0x0B}),
            (ByteVec{0x0B, 0x94, 0x0C, 0x01}));
  // poll added by the owner, here through the explicit connection
  EXPECT_EQ(request({0x4B, 0x03, 0x01, 0x02, kMaster}), (ByteVec{0xCB, 0x00}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kConfiguring);
  EXPECT_GE(slave_->counters().requests_refused, 6u);
}

TEST_F(Cdn127SlaveTest, UnconnectedPortAcceptsOnlyAllocateAndRelease) {
  boot();
  // Get_Attribute_Single on the Group 2 only unconnected port: 0x02/0x03.
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x0E, 0x01, 0x01, 0x01}),
            (ByteVec{kMaster, 0x94, 0x02, 0x03}));
  // Allocate to the wrong object
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x01, 0x01, 0x03, kMaster}),
            (ByteVec{kMaster, 0x94, 0x02, 0x03}));
  // Allocate without its allocator byte
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03}),
            (ByteVec{kMaster, 0x94, 0x13, 0xFF}));
}

TEST_F(Cdn127SlaveTest, ReleaseLeavesTheSlaveUnowned) {
  boot();
  allocate();
  // Release from another master is refused.
  EXPECT_EQ(single(kUnconnectedId, {0x0B, 0x4C, 0x03, 0x01, 0x03}),
            (ByteVec{0x0B, 0x94, 0x0C, 0x01}));
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x02}), (ByteVec{kMaster, 0xCC}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), kMaster);
  // releasing what is not allocated
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x02}),
            (ByteVec{kMaster, 0x94, 0x0B, 0x02}));
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x01}), (ByteVec{kMaster, 0xCC}));
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  // Explicit requests are no longer served; another master may allocate.
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x01}).empty());
  EXPECT_EQ(single(kUnconnectedId, {0x0B, 0x4B, 0x03, 0x01, 0x01, 0x0B}),
            (ByteVec{0x0B, 0xCB, 0x00}));
}

// ---------------------------------------------------------------------------
// Identity, explicit messaging and fragmentation

TEST_F(Cdn127SlaveTest, IdentityValues) {
  boot();
  allocate();
  EXPECT_EQ(get(0x01, 0x01, 0x01), (ByteVec{0x8E, 0x3B, 0x00}));  // vendor 59
  EXPECT_EQ(get(0x01, 0x01, 0x02), (ByteVec{0x8E, 0x1B, 0x00}));  // product type 27
  EXPECT_EQ(get(0x01, 0x01, 0x03), (ByteVec{0x8E, 0x60, 0x07}));  // product code 1888
  EXPECT_EQ(get(0x01, 0x01, 0x04), (ByteVec{0x8E, 0x01, 0x05}));  // revision 1.5
  EXPECT_EQ(get(0x01, 0x01, 0x06), (ByteVec{0x8E, 0x34, 0x12}));  // serial as UINT
  EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, 0x03}));        // operating
  // class attributes 1, 2, 6, 7
  EXPECT_EQ(get(0x01, 0x00, 0x01), (ByteVec{0x8E, 0x01, 0x00}));
  EXPECT_EQ(get(0x01, 0x00, 0x02), (ByteVec{0x8E, 0x01, 0x00}));
  EXPECT_EQ(get(0x01, 0x00, 0x06), (ByteVec{0x8E, 0x07, 0x00}));
  EXPECT_EQ(get(0x01, 0x00, 0x07), (ByteVec{0x8E, 0x07, 0x00}));
  EXPECT_EQ(get(0x01, 0x00, 0x03), error(0x14));
}

TEST_F(Cdn127SlaveTest, SerialNumberAsUdintOption) {
  SlaveOptions o = default_options();
  o.serial_number = 0x00ABCDEF;
  o.serial_number_udint = true;
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x01, 0x01, 0x06), (ByteVec{0x8E, 0xEF, 0xCD, 0xAB, 0x00}));
}

TEST_F(Cdn127SlaveTest, ExplicitResponseEchoesXidAndMac) {
  boot();
  allocate();
  // XID set in the request header: echoed.
  EXPECT_EQ(single(kRequestId, {0x4A, 0x0E, 0x01, 0x01, 0x01}), (ByteVec{0x4A, 0x8E, 0x3B, 0x00}));
}

TEST_F(Cdn127SlaveTest, ProductNameComesInAcknowledgedFragments) {
  boot();
  allocate();
  auto out = exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x07});
  ASSERT_EQ(out.size(), 1u);
  // first fragment: [Frag|M=10][first, count 0][8E 06 'C' 'D' 'N' '1']
  EXPECT_EQ(hex(out[0]), "41B: 8A 00 8E 06 43 44 4E 31");
  // no second fragment before the ack
  advance(milliseconds(100));
  EXPECT_TRUE(sink_.take().empty());
  out = exchange(kRequestId, {0x8A, 0xC0, 0x00});
  ASSERT_EQ(out.size(), 1u);
  // last fragment, count 1: '2' '7'
  EXPECT_EQ(hex(out[0]), "41B: 8A 81 32 37");
  EXPECT_TRUE(exchange(kRequestId, {0x8A, 0xC1, 0x00}).empty());

  // The same through the helper that acks as a master does.
  EXPECT_EQ(get(0x01, 0x01, 0x07), (ByteVec{0x8E, 0x06, 'C', 'D', 'N', '1', '2', '7'}));
}

TEST_F(Cdn127SlaveTest, UnackedFragmentIsResentOnceThenAbandoned) {
  boot();
  allocate();
  auto first = exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x07});
  ASSERT_EQ(first.size(), 1u);
  advance(milliseconds(1000));
  auto resent = sink_.take();
  ASSERT_EQ(resent.size(), 1u);
  EXPECT_EQ(resent[0], first[0]);
  advance(milliseconds(1000));
  EXPECT_TRUE(sink_.take().empty());
  EXPECT_EQ(slave_->counters().fragment_transfers_failed, 1u);
}

TEST_F(Cdn127SlaveTest, FragmentedRequestIsReassembled) {
  boot();
  allocate();
  // Set the poll consumed path with the 16-bit form (12-byte message):
  // [10][05][02][16] 21 04 00 25 64 00 30 03 = assembly 100, attribute 3
  EXPECT_EQ(request({0x10, 0x05, 0x02, 0x10, 0x21, 0x04, 0x00, 0x25, 0x64, 0x00, 0x30, 0x03}),
            (ByteVec{0x90}));
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x64, 0x30, 0x03}));
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x03, 0x00}));  // consumed size 3
}

}  // namespace
}  // namespace dnbridge::sim
