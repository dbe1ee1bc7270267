// The simulated CDN127 and the Group 4 Offline Connection Set, frame by frame
// with a fake clock: a node faulted by a duplicate MAC is found, owned, given
// a new MAC and comes online there. Slave MAC 3 (software MAC: switch in the
// program position), vendor 59 (0x3B), serial 0x1234; tool MAC 10.
//   0x7EC Communication Faulted Response   0x7ED Communication Faulted Request
//   0x7EE Offline Ownership Response       0x7EF Offline Ownership Request
#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <vector>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "support/bytes.hpp"
#include "support/sim_slave_driver.hpp"

namespace dnbridge::sim {
namespace {

using devicenet::CommFaultedLayout;
using devicenet::OwnershipIdentity;
using test::ByteVec;
using test::hex;
using State = Cdn127Slave::NetworkState;

constexpr std::uint32_t kCommFaultedResponse = 0x7EC;
constexpr std::uint32_t kCommFaultedRequest = 0x7ED;
constexpr std::uint32_t kOwnershipRequest = 0x7EF;
constexpr std::uint32_t kDupMacMac3 = 0x41F;

using test::RecordingSink;

SlaveOptions program_position_options() {
  SlaveOptions o;
  o.mac_switch = 99;  // program position: MAC from E2
  o.baud_switch = 2;
  o.stored_mac = 3;
  o.serial_number = 0x1234;
  return o;
}

class OfflineConnectionTest : public ::testing::Test {
 protected:
  void create(SlaveOptions options = program_position_options()) {
    slave_ = std::make_unique<Cdn127Slave>(sink_, options);
  }
  void SetUp() override { create(); }

  void advance(Duration d) { test::advance(*slave_, now_, d); }

  // Power-up, then another node (vendor 1, serial 99) checks MAC 3 during
  // the first window: Communication Fault.
  void fault_by_duplicate() {
    slave_->power_on(now_);
    advance(milliseconds(500));
    slave_->on_frame(test::frame(kDupMacMac3, {0x00, 0x01, 0x00, 0x63, 0x00, 0x00, 0x00}), now_);
    ASSERT_EQ(slave_->network_state(), State::kCommunicationFault);
    sink_.take();
  }

  // The frames the slave sends in answer to one frame, as "ID: bytes".
  std::vector<std::string> exchange(std::uint32_t id, std::initializer_list<std::uint8_t> data) {
    sink_.take();
    slave_->on_frame(test::frame(id, data), now_);
    std::vector<std::string> out;
    for (const auto& f : sink_.take()) out.push_back(hex(f));
    return out;
  }
  using Frames = std::vector<std::string>;

  // Ownership for tool MAC 10 of this node (vendor 59, serial 0x1234).
  void take_ownership() {
    // 0A client MAC 10 | 01 allocate | 3B 00 vendor 59 | 34 12 00 00 serial
    EXPECT_EQ(exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
              Frames{"7EE: 0A 81 3B 00 34 12 00 00"});
    ASSERT_TRUE(slave_->offline_owner().has_value());
  }

  RecordingSink sink_;
  std::unique_ptr<Cdn127Slave> slave_;
  TimePoint now_ = TimePoint{} + seconds(100);
};

TEST_F(OfflineConnectionTest, FaultedNodeIsRecoveredToANewMacAndComesOnlineThere) {
  fault_by_duplicate();

  // Who is communication faulted? Short form, match 0: every faulted node.
  // 3F: match 0, value 63 | 4B: request, identify.
  // Answer: 03 value = MAC 3 | CB: response, identify | 3B 00 vendor | 34 12 00 00 serial.
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x3F, 0x4B}), Frames{"7EC: 03 CB 3B 00 34 12 00 00"});

  take_ownership();
  EXPECT_EQ(slave_->offline_owner()->value(), 10);

  // Set MAC 7, long form naming the node: 07 value = new MAC | 10 Set_Attribute_Single |
  // vendor | serial. Echoed with R/R set, then the duplicate MAC check at MAC 7.
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            (Frames{"7EC: 07 90 3B 00 34 12 00 00", "43F: 00 3B 00 34 12 00 00"}));
  EXPECT_EQ(slave_->mac().value(), 7);
  EXPECT_EQ(slave_->network_state(), State::kDuplicateMacCheck);
  EXPECT_FALSE(slave_->offline_owner().has_value());
  EXPECT_EQ(slave_->device().e2().mac, 7);

  advance(milliseconds(2001));
  EXPECT_EQ(slave_->network_state(), State::kOnline);
  // A master allocates at MAC 7: 0x43E Allocate explicit, answered on 0x43B.
  EXPECT_EQ(exchange(0x43E, {0x0A, 0x4B, 0x03, 0x01, 0x01, 0x0A}), Frames{"43B: 0A CB 00"});
  EXPECT_EQ(slave_->counters().offline_responses, 3u);

  // Online, the offline set is ignored.
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x4B}).empty());
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
}

TEST_F(OfflineConnectionTest, RecoveryAtTheSameMacRerunsTheDuplicateCheck) {
  fault_by_duplicate();
  take_ownership();
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x03, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            (Frames{"7EC: 03 90 3B 00 34 12 00 00", "41F: 00 3B 00 34 12 00 00"}));
  EXPECT_EQ(slave_->network_state(), State::kDuplicateMacCheck);
  advance(milliseconds(2001));
  EXPECT_EQ(slave_->network_state(), State::kOnline);
  EXPECT_EQ(slave_->mac().value(), 3);
}

TEST_F(OfflineConnectionTest, NodesNotInCommunicationFaultIgnoreTheSet) {
  // Before power-up, during the check and online: silence.
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x4B}).empty());
  slave_->power_on(now_);
  sink_.take();
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x4B}).empty());
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  advance(milliseconds(2001));
  ASSERT_EQ(slave_->network_state(), State::kOnline);
  sink_.take();
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->mac().value(), 3);
  EXPECT_FALSE(slave_->offline_owner().has_value());
}

TEST_F(OfflineConnectionTest, IdentifyAnswersOnlyWhenTheRequestMatches) {
  fault_by_duplicate();
  // match 1, value 5: another MAC.
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x45, 0x4B}).empty());
  // match 1, value 3: this node.
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x43, 0x4B}), Frames{"7EC: 03 CB 3B 00 34 12 00 00"});
  // The ICP DAS form with a time delay byte offset: answered (at once).
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x3F, 0x4B, 0x02}),
            Frames{"7EC: 03 CB 3B 00 34 12 00 00"});
  // Long form: by vendor + serial.
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x00, 0x4B, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            Frames{"7EC: 03 CB 3B 00 34 12 00 00"});
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x00, 0x4B, 0x3B, 0x00, 0x35, 0x12, 0x00, 0x00}).empty());
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x00, 0x4B, 0x3C, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  // Other services, responses, malformed lengths: silence.
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x0E}).empty());
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0xCB}).empty());
  EXPECT_TRUE(
      exchange(kCommFaultedResponse, {0x03, 0xCB, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x4B, 0x00, 0x00}).empty());
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F}).empty());
  EXPECT_TRUE(exchange(0x7C0, {0x3F, 0x4B}).empty());
  EXPECT_EQ(slave_->network_state(), State::kCommunicationFault);
}

TEST_F(OfflineConnectionTest, IdentifyResponseInTheVendorManualLayout) {
  SlaveOptions o = program_position_options();
  o.offline.identify_response = CommFaultedLayout::kPortVendorSerial;
  create(o);
  fault_by_duplicate();
  // 00 port | 3B 00 vendor | 34 12 00 00 serial
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x3F, 0x4B, 0x02}), Frames{"7EC: 00 3B 00 34 12 00 00"});
}

TEST_F(OfflineConnectionTest, SetMacNeedsOwnershipAndMustNameTheNode) {
  fault_by_duplicate();
  // No ownership yet: refused, silently.
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->counters().requests_refused, 1u);
  // Ownership naming another node (kTarget): not for us.
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x99, 0x00, 0x00, 0x00}).empty());
  EXPECT_FALSE(slave_->offline_owner().has_value());
  take_ownership();
  // Another client cannot take it over.
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0B, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->offline_owner()->value(), 10);
  // The owner asks again: answered.
  EXPECT_EQ(exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            Frames{"7EE: 0A 81 3B 00 34 12 00 00"});
  // Set MAC naming another serial: not for us.
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x35, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->mac().value(), 3);
  // Release (allocate 0), then the MAC change is refused again.
  EXPECT_EQ(exchange(kOwnershipRequest, {0x0A, 0x00, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            Frames{"7EE: 0A 80 3B 00 34 12 00 00"});
  EXPECT_FALSE(slave_->offline_owner().has_value());
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->network_state(), State::kCommunicationFault);
}

TEST_F(OfflineConnectionTest, MacFromTheSwitchCannotBeChangedOffline) {
  SlaveOptions o = program_position_options();
  o.mac_switch = 3;  // a valid switch governs the MAC
  create(o);
  fault_by_duplicate();
  take_ownership();
  EXPECT_TRUE(
      exchange(kCommFaultedRequest, {0x07, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->network_state(), State::kCommunicationFault);
  EXPECT_EQ(slave_->mac().value(), 3);
}

TEST_F(OfflineConnectionTest, ClientIdentityOwnershipIsAnsweredByAnyFaultedNode) {
  SlaveOptions o = program_position_options();
  o.offline.ownership_identity = OwnershipIdentity::kClient;
  create(o);
  fault_by_duplicate();
  // The tool's own vendor 1 and serial 0xDB000001.
  EXPECT_EQ(exchange(kOwnershipRequest, {0x0A, 0x01, 0x01, 0x00, 0x01, 0x00, 0x00, 0xDB}),
            Frames{"7EE: 0A 81 01 00 01 00 00 DB"});
  // The same MAC with another identity is another client.
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x01, 0x00, 0x02, 0x00, 0x00, 0xDB}).empty());
  EXPECT_EQ(exchange(kCommFaultedRequest, {0x09, 0x10, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}),
            (Frames{"7EC: 09 90 3B 00 34 12 00 00", "44F: 00 3B 00 34 12 00 00"}));
}

TEST_F(OfflineConnectionTest, UnsupportedSetIsIgnored) {
  SlaveOptions o = program_position_options();
  o.offline.supported = false;
  create(o);
  fault_by_duplicate();
  EXPECT_TRUE(exchange(kCommFaultedRequest, {0x3F, 0x4B}).empty());
  EXPECT_TRUE(
      exchange(kOwnershipRequest, {0x0A, 0x01, 0x3B, 0x00, 0x34, 0x12, 0x00, 0x00}).empty());
}

TEST_F(OfflineConnectionTest, PowerCycleDropsOwnership) {
  fault_by_duplicate();
  take_ownership();
  slave_->power_cycle(now_);
  EXPECT_FALSE(slave_->offline_owner().has_value());
}

}  // namespace
}  // namespace dnbridge::sim
