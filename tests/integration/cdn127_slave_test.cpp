// The simulated CDN127 driven frame by frame with a fake clock: what a master
// sees on the wire. Slave MAC 3, master MAC 10 unless a test says otherwise:
//   0x41B explicit/unconnected response   0x41C explicit request
//   0x41D poll command                    0x41E Allocate/Release
//   0x41F duplicate MAC check             0x3C3 poll response
#include "adapters/sim/cdn127/cdn127_slave.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "support/bytes.hpp"
#include "support/sim_slave_driver.hpp"

namespace dnbridge::sim {
namespace {

using test::ByteVec;
using test::frame;
using test::hex;

constexpr std::uint32_t kResponseId = 0x41B;
constexpr std::uint32_t kRequestId = 0x41C;
constexpr std::uint32_t kPollId = 0x41D;
constexpr std::uint32_t kUnconnectedId = 0x41E;
constexpr std::uint32_t kDupMacId = 0x41F;
constexpr std::uint32_t kPollResponseId = 0x3C3;
constexpr std::uint8_t kMaster = 10;  // 0x0A

using test::RecordingSink;

can::CanFrame make(std::uint32_t id, const ByteVec& data) {
  return can::CanFrame::make(id, Bytes(data.data(), data.size())).value();
}

ByteVec bytes_of(const can::CanFrame& f) { return ByteVec(f.data.begin(), f.data.begin() + f.len); }

SlaveOptions default_options() {
  SlaveOptions o;
  o.mac_switch = 3;   // valid: MAC 3 from the switch
  o.baud_switch = 2;  // valid: 500k
  o.serial_number = 0x1234;
  o.pump.spin_up = seconds(3);
  o.pump.spin_down = seconds(5);
  return o;
}

class Cdn127SlaveTest : public ::testing::Test {
 protected:
  void create(SlaveOptions options = default_options()) {
    slave_ = std::make_unique<Cdn127Slave>(sink_, options);
  }
  void SetUp() override { create(); }

  // Runs the slave's timers up to now + d, as an event loop would.
  void advance(Duration d) { test::advance(*slave_, now_, d); }

  // Power-up and the 2 s duplicate MAC check.
  void boot() {
    slave_->power_on(now_);
    advance(milliseconds(2001));
    ASSERT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
    sink_.take();
  }

  std::vector<can::CanFrame> exchange(std::uint32_t id, const ByteVec& data) {
    sink_.take();
    slave_->on_frame(make(id, data), now_);
    return sink_.take();
  }
  // One frame expected in answer; its payload.
  ByteVec single(std::uint32_t id, const ByteVec& data, std::uint32_t expected_id = kResponseId) {
    auto out = exchange(id, data);
    EXPECT_EQ(out.size(), 1u);
    if (out.size() != 1) return {};
    EXPECT_EQ(out[0].id, expected_id);
    return bytes_of(out[0]);
  }

  // Allocate explicit + poll for master 10 and check the success response.
  void allocate(std::uint8_t choice = 0x03) {
    EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, choice, kMaster}),
              (ByteVec{kMaster, 0xCB, 0x00}));
  }

  // An explicit request (service byte first) on the explicit connection; the
  // whole response message, reassembled and acked as a master does.
  ByteVec request(const ByteVec& message) {
    sink_.take();
    if (message.size() <= 7) {
      ByteVec p{kMaster};
      p.insert(p.end(), message.begin(), message.end());
      slave_->on_frame(make(kRequestId, p), now_);
    } else {
      // Acknowledged fragments of 6 bytes; the slave acks each on 0x41B.
      std::size_t off = 0;
      std::uint8_t count = 0;
      while (off < message.size()) {
        const std::size_t n = std::min<std::size_t>(6, message.size() - off);
        const std::uint8_t type = off == 0 ? 0 : (off + n == message.size() ? 2 : 1);
        ByteVec p{static_cast<std::uint8_t>(0x80 | kMaster),
                  static_cast<std::uint8_t>((type << 6) | count)};
        p.insert(p.end(), message.begin() + static_cast<std::ptrdiff_t>(off),
                 message.begin() + static_cast<std::ptrdiff_t>(off + n));
        slave_->on_frame(make(kRequestId, p), now_);
        auto ack = sink_.take();
        EXPECT_GE(ack.size(), 1u);
        if (ack.empty()) return {};
        EXPECT_EQ(bytes_of(ack[0]), (ByteVec{static_cast<std::uint8_t>(0x80 | kMaster),
                                             static_cast<std::uint8_t>(0xC0 | count), 0x00}));
        // The response's first frame may follow the last ack.
        for (std::size_t i = 1; i < ack.size(); ++i) sink_.frames.push_back(ack[i]);
        off += n;
        ++count;
      }
    }
    return collect_response();
  }

  ByteVec collect_response() {
    auto out = sink_.take();
    EXPECT_EQ(out.size(), 1u);
    if (out.size() != 1) return {};
    EXPECT_EQ(out[0].id, kResponseId);
    ByteVec p = bytes_of(out[0]);
    if (p.empty()) return {};
    EXPECT_EQ(p[0] & 0x7F, kMaster);  // XID and MAC echoed
    if ((p[0] & 0x80) == 0) return ByteVec(p.begin() + 1, p.end());
    // Fragmented response: ack every fragment on 0x41C until the last.
    ByteVec message;
    for (int guard = 0; guard < 100; ++guard) {
      EXPECT_GE(p.size(), 2u);
      const std::uint8_t frag = p[1];
      message.insert(message.end(), p.begin() + 2, p.end());
      auto next = exchange(kRequestId, {static_cast<std::uint8_t>(0x80 | kMaster),
                                        static_cast<std::uint8_t>(0xC0 | (frag & 0x3F)), 0x00});
      if ((frag >> 6) == 2) {
        EXPECT_TRUE(next.empty());
        return message;
      }
      EXPECT_EQ(next.size(), 1u);
      if (next.size() != 1) return {};
      p = bytes_of(next[0]);
    }
    return {};
  }

  ByteVec get(std::uint8_t cls, std::uint8_t inst, std::uint8_t attr) {
    return request({0x0E, cls, inst, attr});
  }
  ByteVec set(std::uint8_t cls, std::uint8_t inst, std::uint8_t attr, const ByteVec& data) {
    ByteVec m{0x10, cls, inst, attr};
    m.insert(m.end(), data.begin(), data.end());
    return request(m);
  }
  static ByteVec error(std::uint8_t status, std::uint8_t additional = 0xFF) {
    return {0x94, status, additional};
  }

  // Allocate, set the poll EPR and return the actual value.
  void establish_poll(std::uint16_t epr_ms = 100) {
    allocate();
    const ByteVec r =
        set(0x05, 0x02, 0x09,
            {static_cast<std::uint8_t>(epr_ms & 0xFF), static_cast<std::uint8_t>(epr_ms >> 8)});
    ASSERT_EQ(r.size(), 3u);
    ASSERT_EQ(r[0], 0x90);
    ASSERT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  }

  ByteVec poll(const ByteVec& command) {
    auto out = exchange(kPollId, command);
    EXPECT_EQ(out.size(), 1u);
    if (out.size() != 1) return {};
    EXPECT_EQ(out[0].id, kPollResponseId);
    return bytes_of(out[0]);
  }

  RecordingSink sink_;
  std::unique_ptr<Cdn127Slave> slave_;
  TimePoint now_{};
};

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

// ---------------------------------------------------------------------------
// Connection object

TEST_F(Cdn127SlaveTest, ExpectedPacketRateRoundsUpToTheTimerResolution) {
  boot();
  allocate();
  // Set EPR 3594 ms -> the device keeps and returns 3600 (bridge/PROTOCOL.md §7).
  EXPECT_EQ(single(kRequestId, {kMaster, 0x10, 0x05, 0x02, 0x09, 0x0A, 0x0E}),
            (ByteVec{kMaster, 0x90, 0x10, 0x0E}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(get(0x05, 0x02, 0x09), (ByteVec{0x8E, 0x10, 0x0E}));
  EXPECT_EQ(get(0x05, 0x02, 0x01), (ByteVec{0x8E, 0x03}));
  // explicit connection: default 2500 ms
  EXPECT_EQ(get(0x05, 0x01, 0x09), (ByteVec{0x8E, 0xC4, 0x09}));
}

TEST_F(Cdn127SlaveTest, ConnectionAttributes) {
  boot();
  allocate();
  // explicit instance 1
  EXPECT_EQ(get(0x05, 0x01, 0x01), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x05, 0x01, 0x02), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x03), (ByteVec{0x8E, 0x83}));
  EXPECT_EQ(get(0x05, 0x01, 0x04), (ByteVec{0x8E, 0x1B, 0x04}));  // 0x41B
  EXPECT_EQ(get(0x05, 0x01, 0x05), (ByteVec{0x8E, 0x1C, 0x04}));  // 0x41C
  EXPECT_EQ(get(0x05, 0x01, 0x06), (ByteVec{0x8E, 0x21}));
  EXPECT_EQ(get(0x05, 0x01, 0x07), (ByteVec{0x8E, 0x18, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x08), (ByteVec{0x8E, 0x18, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0C), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x01, 0x0D), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0E), (ByteVec{0x8E}));
  EXPECT_EQ(get(0x05, 0x01, 0x11), (ByteVec{0x8E, 0x00, 0x00}));
  EXPECT_EQ(get(0x05, 0x01, 0x0A), error(0x14));
  // explicit watchdog action is fixed (Get only in the manual)
  EXPECT_EQ(set(0x05, 0x01, 0x0C, {0x03}), error(0x0E));
  // poll instance 2, defaults: assemblies 103/104 with the CDN127 preset
  EXPECT_EQ(get(0x05, 0x02, 0x02), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x02, 0x03), (ByteVec{0x8E, 0x82}));
  EXPECT_EQ(get(0x05, 0x02, 0x04), (ByteVec{0x8E, 0xC3, 0x03}));  // 0x3C3
  EXPECT_EQ(get(0x05, 0x02, 0x05), (ByteVec{0x8E, 0x1D, 0x04}));  // 0x41D
  EXPECT_EQ(get(0x05, 0x02, 0x06), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x06, 0x00}));  // DSUP DIN AIN AIN
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x04, 0x00}));  // DOUT PAD AOUT
  EXPECT_EQ(get(0x05, 0x02, 0x0C), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x0D), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x05, 0x02, 0x0E), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x67, 0x30, 0x03}));
  EXPECT_EQ(get(0x05, 0x02, 0x0F), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x68, 0x30, 0x03}));
  // watchdog action 0..3 on the poll connection
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x04}), error(0x09));
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x02}), (ByteVec{0x90}));
  // produced path: assembly 2 (exception byte, input byte)
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x02, 0x30, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  // a consumed assembly named as produced, and a path to another class
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x05, 0x30, 0x03}), error(0x09));
  EXPECT_EQ(set(0x05, 0x02, 0x10, {0x20, 0x01, 0x24, 0x01, 0x30, 0x03}), error(0x09));
  // class attribute 1 only
  EXPECT_EQ(get(0x05, 0x00, 0x01), (ByteVec{0x8E, 0x01, 0x00}));
  EXPECT_EQ(get(0x05, 0x00, 0x02), error(0x14));
  // paths are fixed once the connection is established
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x01, 0x30, 0x03}), error(0x0C));
}

// A firmware without the poll connection's Produced/Consumed Size answers
// them as attributes it has not (0x14), on Get and Set alike; the
// Configuration object's Number Produced/Consumed still answer, in USINT.
TEST_F(Cdn127SlaveTest, FirmwareWithoutConnectionSizesRefusesThemWithAttributeNotSupported) {
  SlaveOptions o = default_options();
  o.unsupported_attributes = {{0x05, 7}, {0x05, 8}};
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x05, 0x02, 0x07), error(0x14));
  EXPECT_EQ(get(0x05, 0x02, 0x08), error(0x14));
  EXPECT_EQ(get(0x05, 0x01, 0x07), error(0x14));
  EXPECT_EQ(set(0x05, 0x02, 0x07, {0x06, 0x00}), error(0x14));  // not 0x0E: it has none
  EXPECT_EQ(get(0x05, 0x02, 0x0D), (ByteVec{0x8E, 0x06}));      // the rest as before
  EXPECT_EQ(get(0x40, 0x01, 16), (ByteVec{0x8E, 0x06}));        // DSUP DIN AIN AIN
  EXPECT_EQ(get(0x40, 0x01, 17), (ByteVec{0x8E, 0x04}));        // DOUT PAD AOUT
}

// A firmware that has an attribute Get only although the manual lists it
// Get/Set: its Get answers, its Set is refused with 0x0E and changes nothing.
TEST_F(Cdn127SlaveTest, FirmwareWithAReadOnlyAttributeAnswersItsGetAndRefusesItsSet) {
  SlaveOptions o = default_options();
  o.read_only_attributes = {{0x0B, 9}};
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x0B, 0x01, 9), (ByteVec{0x8E, 0x00}));  // AOP Fault State: hold
  EXPECT_EQ(set(0x0B, 0x01, 9, {0x03}), error(0x0E));
  EXPECT_EQ(slave_->device().e2().aop.fault_state, 0);
  EXPECT_EQ(set(0x0B, 0x01, 10, {0x03}), (ByteVec{0x90}));  // the others as before
  EXPECT_EQ(slave_->device().e2().aop.idle_state, 3);
}

TEST_F(Cdn127SlaveTest, PollConnectionDoesNotExistBeforeAllocation) {
  boot();
  allocate(0x01);
  EXPECT_EQ(get(0x05, 0x02, 0x01), error(0x16));
  EXPECT_EQ(get(0x05, 0x03, 0x01), error(0x16));
}

// ---------------------------------------------------------------------------
// Poll I/O

TEST_F(Cdn127SlaveTest, PollRoundTripWithTheCdn127Preset) {
  boot();
  ASSERT_TRUE(slave_->pump().set_analog_input(0, 0x0123));
  ASSERT_TRUE(slave_->pump().set_analog_input(1, 0x0FFF));
  establish_poll(1000);  // watchdog 4 s: outlives the spin-up wait below
  // request: [DOUT: pump on | N2 ballast][PAD][AOUT 0x0800 LE]
  const ByteVec r = poll({0x05, 0x00, 0x00, 0x08});
  // response: [DSUP: expanded mode, no alarm][DIN: no warning, N2 ok, no alarm,
  // interlock ok; not running yet][AIN1 LE][AIN2 LE]
  EXPECT_EQ(r, (ByteVec{0x80, 0x1E, 0x23, 0x01, 0xFF, 0x0F}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0800);
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kPoll);
  // The pump runs after its spin-up delay.
  advance(seconds(3));
  EXPECT_EQ(poll({0x05, 0x00, 0x00, 0x08}), (ByteVec{0x80, 0x1F, 0x23, 0x01, 0xFF, 0x0F}));
  // DOP/AOP/AIP/DIP read the same state
  EXPECT_EQ(get(0x09, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x09, 0x02, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x0B, 0x01, 0x03), (ByteVec{0x8E, 0x00, 0x08}));
  EXPECT_EQ(get(0x0A, 0x01, 0x03), (ByteVec{0x8E, 0x23, 0x01}));
  EXPECT_EQ(get(0x08, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x04, 0x68, 0x03), (ByteVec{0x8E, 0x05, 0x00, 0x00, 0x08}));  // assembly 104
  EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x04}));                    // Executing
  EXPECT_EQ(slave_->counters().polls_applied, 2u);
}

TEST_F(Cdn127SlaveTest, PollRoundTripWithTheCdn118Preset) {
  boot();
  allocate();
  // Configuration Reset to the CDN118 preset while the poll connection configures.
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x03, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // request: [DOUT: pump on][AOUT 4095 LE] (NoEvenByte: no pad)
  // response: [DSUP][DIN]
  EXPECT_EQ(poll({0x01, 0xFF, 0x0F}), (ByteVec{0x80, 0x1E}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 4095);
}

TEST_F(Cdn127SlaveTest, NoPollUpdateIsObservableWithAnInstantPump) {
  SlaveOptions o = default_options();
  o.pump.spin_up = Duration::zero();
  o.pump.spin_down = Duration::zero();
  create(o);
  boot();
  establish_poll();
  // CDN127 preset (Mode 0x86, NoPollUpdate): inputs sampled before the outputs change.
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00})[1] & 0x01, 0);
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00})[1] & 0x01, 1);

  // CDN118 preset (Mode 0x81): I/O updated during poll processing.
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x03}), (ByteVec{kMaster, 0xCC}));
  allocate();
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  ASSERT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(poll({0x00, 0x00, 0x00})[1] & 0x01, 0);
  EXPECT_EQ(poll({0x01, 0x00, 0x00})[1] & 0x01, 1);
}

TEST_F(Cdn127SlaveTest, ShortPollIsIdleAndAppliesIdleActions) {
  boot();
  allocate();
  // DOP 2 (ballast) holds on idle; AOP idle state 3 with idle value 1000.
  EXPECT_EQ(set(0x09, 0x02, 0x07, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0A, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0C, {0xE8, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x00, 0x08});
  ASSERT_TRUE(slave_->outputs().pump_on);

  // 0-byte poll: idle. Still answered.
  const ByteVec r = poll({});
  EXPECT_EQ(r.size(), 6u);
  EXPECT_FALSE(slave_->outputs().pump_on);       // idle value 0
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // held
  EXPECT_EQ(slave_->outputs().analog_out_raw, 1000);
  EXPECT_TRUE(slave_->pump().last_change_was_idle());
  EXPECT_EQ(slave_->counters().polls_idle, 1u);
  EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x02}));  // Device Supervisor: Idle
  // A short but non-empty poll is idle too.
  poll({0x01});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_idle, 2u);
}

TEST_F(Cdn127SlaveTest, ZeroConsumedSizeHasNoIdleCondition) {
  boot();
  allocate();
  // No digital or analog outputs: consumed size 0.
  EXPECT_EQ(set(0x40, 0x01, 0x03, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x40, 0x01, 0x05, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_idle, 0u);
  EXPECT_EQ(slave_->counters().polls_applied, 1u);
}

TEST_F(Cdn127SlaveTest, OversizePollIsIgnored) {
  boot();
  establish_poll();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->counters().polls_oversize, 1u);
  EXPECT_FALSE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, PollIgnoredUntilEstablished) {
  boot();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  allocate();
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  EXPECT_EQ(slave_->counters().polls_ignored, 2u);
}

TEST_F(Cdn127SlaveTest, AnalogOutputOverRangeInAPollKeepsTheOutputs) {
  boot();
  establish_poll();
  const ByteVec r = poll({0x01, 0x00, 0x00, 0x10});  // 4096
  EXPECT_EQ(r.size(), 6u);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_invalid, 1u);
}

// ---------------------------------------------------------------------------
// Watchdogs and fault actions

TEST_F(Cdn127SlaveTest, SilencePastFourTimesEprAppliesFaultActionsAndReleases) {
  boot();
  allocate();
  // DOP 2 fault value on; AOP fault state 2 (high limit).
  EXPECT_EQ(set(0x09, 0x02, 0x06, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x02}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));  // 100 ms
  poll({0x01, 0x00, 0x00, 0x01});
  ASSERT_TRUE(slave_->outputs().pump_on);

  advance(milliseconds(399));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_TRUE(slave_->outputs().pump_on);
  advance(milliseconds(1));
  // Watchdog action 0: timed out; outputs to their fault states.
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_FALSE(slave_->outputs().pump_on);       // fault value 0
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // fault value 1
  EXPECT_EQ(slave_->outputs().analog_out_raw, 4095);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());
  // Polls are not consumed by a timed-out connection.
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  // The explicit connection still stands: the master still owns the slave.
  EXPECT_EQ(slave_->owner(), kMaster);
  // With the explicit connection silent for 4 x 2500 ms nothing is left
  // established: the slave releases everything.
  advance(seconds(10));
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_EQ(slave_->device().watchdog_timeouts(), 2u);
  allocate();  // the master must allocate again
}

TEST_F(Cdn127SlaveTest, PollsAndRequestsKeepTheWatchdogsFed) {
  boot();
  establish_poll(100);
  for (int i = 0; i < 100; ++i) {
    advance(milliseconds(300));
    poll({0x01, 0x00, 0x00, 0x00});
    if (i % 10 == 0) get(0x01, 0x01, 0x01);  // every 3 s: within 4 x 2500 ms
  }
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kEstablished);
  EXPECT_TRUE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, AutoDeleteWithoutExplicitReleasesAtOnce) {
  boot();
  establish_poll(100);
  EXPECT_EQ(set(0x05, 0x02, 0x0C, {0x01}), (ByteVec{0x90}));  // auto delete
  // The explicit connection's EPR can be raised; here it is left to expire first.
  for (int i = 0; i < 40; ++i) {  // 10 s of polls, no explicit requests
    advance(milliseconds(250));
    poll({0x01, 0x00, 0x00, 0x00});
  }
  EXPECT_EQ(slave_->explicit_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), kMaster);  // the poll connection still runs
  advance(milliseconds(400));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kNonExistent);
  EXPECT_EQ(slave_->owner(), 255);
  EXPECT_FALSE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, ConnectionResetRevivesATimedOutPoll) {
  boot();
  establish_poll(100);
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_EQ(request({0x05, 0x05, 0x02}), (ByteVec{0x85}));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00}).size(), 6u);
}

TEST_F(Cdn127SlaveTest, FaultHoldKeepsOutputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x01}), (ByteVec{0x90}));  // hold
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x00}), (ByteVec{0x90}));  // hold
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x01, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  EXPECT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
}

// ---------------------------------------------------------------------------
// Configuration object

TEST_F(Cdn127SlaveTest, ConfigurationChangeRefusedWhilePolling) {
  boot();
  allocate();
  // Before the poll connection is established: accepted, sizes follow.
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x04}));  // DSUP DIN AIN
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x04, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // Established: object state conflict, for Set and Reset alike.
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x02}), error(0x0C));
  EXPECT_EQ(set(0x40, 0x01, 0x0A, {0x01}), error(0x0C));
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x00}), error(0x0C));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x01}));
  // Out of range values
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x02}), (ByteVec{kMaster, 0xCC}));
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x03}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x05, {0x02}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x02, {0x09}), error(0x09));
  EXPECT_EQ(set(0x40, 0x01, 0x01, {0x88}), error(0x09));  // bits 3..5 "should be 0"
  EXPECT_EQ(set(0x40, 0x01, 0x10, {0x01}), error(0x0E));
}

TEST_F(Cdn127SlaveTest, ConfigurationResetPresets) {
  boot();
  allocate(0x01);
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x81}));
  EXPECT_EQ(get(0x40, 0x01, 0x02), (ByteVec{0x8E, 0x08}));
  EXPECT_EQ(get(0x40, 0x01, 0x03), (ByteVec{0x8E, 0x08}));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x40, 0x01, 0x05), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x00}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x86}));
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x40, 0x01, 0x10), (ByteVec{0x8E, 0x06}));
  EXPECT_EQ(get(0x40, 0x01, 0x11), (ByteVec{0x8E, 0x04}));
  // bad preset, missing byte, class-level Reset (not listed)
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x02}), error(0x20));
  EXPECT_EQ(request({0x05, 0x40, 0x01}), error(0x13));
  EXPECT_EQ(request({0x05, 0x40, 0x00, 0x00}), error(0x08));
}

TEST_F(Cdn127SlaveTest, NoNcMaskInvertsReportedInputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x40, 0x01, 0x0A, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  // 0x1E ^ 0x03 = 0x1D
  EXPECT_EQ(poll({0x00, 0x00, 0x00, 0x00})[1], 0x1D);
  EXPECT_EQ(get(0x08, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x08, 0x02, 0x03), (ByteVec{0x8E, 0x00}));
}

// ---------------------------------------------------------------------------
// Device Supervisor, exception status

TEST_F(Cdn127SlaveTest, ExceptionStatusFollowsThePumpAndTheEnables) {
  boot();
  allocate();
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x80}));
  slave_->pump().set_alarm(true, now_);
  slave_->pump().set_warning(true);
  // Device Specific Error (bit 1) and Warning (bit 5), expanded mode bit 7
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0xA2}));
  EXPECT_EQ(get(0x32, 0x01, 0x0D), (ByteVec{0x8E, 2, 0, 0, 8, 8, 0, 8, 0, 2, 0, 1, 0, 1, 0x02}));
  EXPECT_EQ(get(0x32, 0x01, 0x0E), (ByteVec{0x8E, 2, 0, 0, 0, 1, 0x01}));
  // Clearing the alarm enable clears the alarm bits
  EXPECT_EQ(set(0x32, 0x01, 0x0F, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0xA0}));
  EXPECT_EQ(get(0x32, 0x01, 0x0D).back(), 0x00);
  EXPECT_EQ(set(0x32, 0x01, 0x10, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x80}));
  EXPECT_EQ(set(0x32, 0x01, 0x10, {0x02}), error(0x09));
  // N2 flow failure is a device specific error too
  EXPECT_EQ(set(0x32, 0x01, 0x0F, {0x01}), (ByteVec{0x90}));
  slave_->pump().set_alarm(false, now_);
  slave_->pump().set_n2_flow_ok(false);
  EXPECT_EQ(get(0x32, 0x01, 0x0C), (ByteVec{0x8E, 0x82}));
}

TEST_F(Cdn127SlaveTest, DeviceSupervisorStrings) {
  boot();
  allocate();
  EXPECT_EQ(get(0x32, 0x01, 0x03), (ByteVec{0x8E, 9, 'A', 'N', 'A', 'L', 'O', 'G', ' ', 'I', 'O'}));
  EXPECT_EQ(get(0x32, 0x01, 0x04), (ByteVec{0x8E, 8, 'E', '0', '0', '-', '0', '0', '0', '0'}));
  EXPECT_EQ(get(0x32, 0x01, 0x05),
            (ByteVec{0x8E, 11, 'D', '.', 'I', '.', 'P', '.', ' ', 'I', 'n', 'c', '.'}));
  EXPECT_EQ(get(0x32, 0x01, 0x06), (ByteVec{0x8E, 6, 'C', 'D', 'N', '1', '2', '7'}));
  EXPECT_EQ(get(0x32, 0x01, 0x07), (ByteVec{0x8E, 6, '0', '1', '.', '0', '0', '5'}));
  EXPECT_EQ(get(0x32, 0x01, 0x08), (ByteVec{0x8E, 6, '0', '1', '.', '0', '0', '0'}));
}

// ---------------------------------------------------------------------------
// DeviceNet object

TEST_F(Cdn127SlaveTest, DeviceNetObjectWithSwitchesInUse) {
  boot();
  allocate();
  EXPECT_EQ(get(0x03, 0x01, 0x01), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x03, 0x01, 0x02), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(get(0x03, 0x01, 0x06), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x03, 0x01, 0x08), (ByteVec{0x8E, 0x03}));
  EXPECT_EQ(get(0x03, 0x01, 0x09), (ByteVec{0x8E, 0x02}));
  // The switches govern: no software setting.
  EXPECT_EQ(set(0x03, 0x01, 0x01, {0x05}), error(0x0E));
  // Turning a switch is seen as "changed" until the next power-up.
  slave_->set_switches(4, 2);
  EXPECT_EQ(get(0x03, 0x01, 0x06), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x03, 0x01, 0x08), (ByteVec{0x8E, 0x04}));
  EXPECT_EQ(slave_->mac().value(), 3);
  // Bus-off counter: set forces 0; allocation info only through Allocate.
  EXPECT_EQ(set(0x03, 0x01, 0x04, {0x07}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x03, 0x01, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(set(0x03, 0x01, 0x05, {0x03, 0x0A}), error(0x0E));
  EXPECT_EQ(set(0x03, 0x01, 0x03, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x03, 0x01, 0x03), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x03, 0x00, 0x01), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x03, 0x00, 0x02), error(0x14));
}

TEST_F(Cdn127SlaveTest, SwitchAttributesNotSupportedInProgramPosition) {
  SlaveOptions o = default_options();
  o.mac_switch = 99;
  o.baud_switch = 9;
  o.stored_mac = 3;
  create(o);
  boot();
  allocate();
  for (std::uint8_t a = 6; a <= 9; ++a) EXPECT_EQ(get(0x03, 0x01, a), error(0x14)) << int(a);
  // Software MAC: the node answers, then comes back with its new MAC.
  EXPECT_EQ(set(0x03, 0x01, 0x01, {0x40}), error(0x09));
  auto out = exchange(kRequestId, {kMaster, 0x10, 0x03, 0x01, 0x01, 0x07});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 90");
  EXPECT_EQ(hex(out[1]), "43F: 00 3B 00 34 12 00 00");  // duplicate MAC check for MAC 7
  EXPECT_EQ(slave_->mac().value(), 7);
  EXPECT_EQ(slave_->owner(), 255);
  // Baud: kept for the next power-up.
  advance(milliseconds(2001));
  EXPECT_EQ(single(0x43E, {kMaster, 0x4B, 0x03, 0x01, 0x01, kMaster}, 0x43B),
            (ByteVec{kMaster, 0xCB, 0x00}));
}

// ---------------------------------------------------------------------------
// Services and attributes the tables do not list

TEST_F(Cdn127SlaveTest, UnlistedServicesAndAttributesGiveTheirErrors) {
  boot();
  allocate();
  EXPECT_EQ(set(0x01, 0x01, 0x01, {0x01, 0x00}), error(0x08));  // Identity has no Set
  EXPECT_EQ(get(0x01, 0x01, 0x09), error(0x14));
  EXPECT_EQ(get(0x01, 0x02, 0x01), error(0x16));  // one instance
  EXPECT_EQ(get(0x07, 0x01, 0x01), error(0x16));  // no such class
  EXPECT_EQ(request({0x4B, 0x01, 0x01, 0x03, kMaster}), error(0x08));
  EXPECT_EQ(request({0x32, 0x01, 0x01}), error(0x08));  // unknown service code
  EXPECT_EQ(get(0x02, 0x00, 0x02), error(0x14));        // Router class: 1, 6, 7
  EXPECT_EQ(get(0x02, 0x00, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x02, 0x01, 0x02), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(set(0x08, 0x01, 0x03, {0x01}), error(0x08));  // DIP: Get only
  EXPECT_EQ(get(0x08, 0x08, 0x03), error(0x16));          // DIP 1..7
  EXPECT_EQ(get(0x08, 0x07, 0x04), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x09, 0x03, 0x03), error(0x16));  // DOP: 2 of max 8
  EXPECT_EQ(get(0x09, 0x00, 0x02), (ByteVec{0x8E, 0x08, 0x00}));
  EXPECT_EQ(set(0x09, 0x01, 0x04, {0x00}), error(0x0E));  // DOP status
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x02}), error(0x09));
  EXPECT_EQ(set(0x09, 0x01, 0x05, {}), error(0x13));
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x01, 0x00}), error(0x15));
  EXPECT_EQ(set(0x0A, 0x01, 0x03, {0x00, 0x00}), error(0x0E));  // AIP: Set listed, nothing settable
  EXPECT_EQ(get(0x0A, 0x01, 0x07), (ByteVec{0x8E, 0x02}));
  EXPECT_EQ(set(0x0B, 0x01, 0x03, {0x00, 0x00}), error(0x0E));  // AOP value: Get
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0x00, 0x10}), error(0x09));  // 4096
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0xFF, 0x0F}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x04}), error(0x09));
  EXPECT_EQ(get(0x0B, 0x01, 0x04), error(0x14));
  EXPECT_EQ(set(0x04, 0x01, 0x03, {0x00}), error(0x0E));  // produced assembly
  EXPECT_EQ(set(0x04, 0x05, 0x03, {}), error(0x13));
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01, 0x00}), error(0x15));
  EXPECT_EQ(get(0x04, 0x04, 0x03), error(0x16));
  EXPECT_EQ(get(0x04, 0x00, 0x02), (ByteVec{0x8E, 0x64, 0x00}));
  EXPECT_EQ(request({0x0E, 0x01, 0x01}), error(0x13));  // no attribute byte
  EXPECT_EQ(request({0x0E, 0x01, 0x01, 0x01, 0x00}), error(0x15));
  EXPECT_EQ(set(0x01, 0x00, 0x01, {0x01, 0x00}), error(0x08));  // class-level Set
}

TEST_F(Cdn127SlaveTest, EveryListedAttributeAnswersGet) {
  boot();
  establish_poll();
  for (const ClassDef& c : object_classes()) {
    for (const ClassAttributeDef& a : c.class_attributes) {
      const ByteVec r = get(c.id, 0, a.id);
      EXPECT_EQ(r, (ByteVec{0x8E, static_cast<std::uint8_t>(a.value & 0xFF),
                            static_cast<std::uint8_t>(a.value >> 8)}))
          << c.name << " class attribute " << int(a.id);
    }
    for (std::uint16_t inst = 1; inst <= 104; ++inst) {
      if (!c.has_instance(slave_->device(), inst)) continue;
      for (const AttributeDef& a : c.instance_attributes) {
        const ByteVec r = get(c.id, static_cast<std::uint8_t>(inst), a.id);
        ASSERT_FALSE(r.empty());
        EXPECT_EQ(r[0], 0x8E) << c.name << " " << inst << "/" << int(a.id) << ": " << hex(r);
      }
    }
  }
}

TEST_F(Cdn127SlaveTest, ConsumedAssemblySetDrivesOutputsUnlessThePollOwnsIt) {
  boot();
  allocate();
  // assembly 100: [outputs][analog LE]
  EXPECT_EQ(set(0x04, 0x64, 0x03, {0x04, 0x10, 0x00}), (ByteVec{0x90}));
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 16);
  EXPECT_EQ(slave_->pump().last_cause(), OutputCause::kExplicit);
  // assembly 5 carries no analog output: the analog value stays
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01}), (ByteVec{0x90}));
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 16);
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x04, 0x68, 0x03, {0x00, 0x00, 0x00, 0x00}), error(0x0C));
  // produced assemblies read the inputs
  EXPECT_EQ(get(0x04, 0x01, 0x03), (ByteVec{0x8E, 0x80}));
  EXPECT_EQ(get(0x04, 0x03, 0x03), (ByteVec{0x8E, 0x1E}));
  EXPECT_EQ(get(0x04, 0x66, 0x03), (ByteVec{0x8E, 0x1E, 0x00, 0x00, 0x00, 0x00, 0x00}));
}

TEST_F(Cdn127SlaveTest, GroupsAndMessagesNotSupportedAreIgnored) {
  boot();
  allocate();
  // Group 3 UCMM request from MAC 10, Group 1 traffic, bit strobe from the master,
  // another slave's poll command.
  EXPECT_TRUE(exchange(0x78A, {0x00, 0x4B, 0x03, 0x01, 0x03, 0x0A}).empty());
  EXPECT_TRUE(exchange(0x3C5, {0x01}).empty());
  EXPECT_TRUE(exchange(0x450, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}).empty());
  EXPECT_TRUE(exchange(0x42D, {0x01, 0x00, 0x00, 0x00}).empty());
  EXPECT_TRUE(exchange(0x41A, {0x00}).empty());  // COS ack to our MAC
  // The master's bit strobe is for every node it owns: ignored by a device
  // without a bit-strobe connection; a bit strobe of another master is not
  // addressed to it.
  EXPECT_TRUE(exchange(0x458, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}).empty());
  EXPECT_EQ(slave_->counters().frames_ignored, 3u);
  EXPECT_EQ(slave_->counters().frames_not_addressed, 3u);
}

// ---------------------------------------------------------------------------
// Factory output actions (SlaveOptions::factory_output_actions)

constexpr std::uint8_t kDopInstances[] = {1, 2};  // Pump On, N2 Ballast On

SlaveOptions unsafe_options() {
  SlaveOptions o = default_options();
  o.factory_output_actions = kUnsafeFactoryOutputActions;
  return o;
}

// The simulator's factory values: every attribute 0, each DOP to Off on a
// fault and on idle, the AOP holding.
TEST_F(Cdn127SlaveTest, DefaultFactoryOutputActionsTurnTheDopsOff) {
  boot();
  allocate();
  for (std::uint8_t instance : kDopInstances) {
    for (std::uint8_t attribute = 5; attribute <= 8; ++attribute) {
      EXPECT_EQ(get(0x09, instance, attribute), (ByteVec{0x8E, 0x00})) << int{attribute};
    }
  }
  EXPECT_EQ(get(0x0B, 0x01, 0x09), (ByteVec{0x8E, 0x00}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));
}

TEST_F(Cdn127SlaveTest, UnsafeFactoryOutputActionsAreWhatTheDeviceAnswers) {
  create(unsafe_options());
  boot();
  allocate();
  for (std::uint8_t instance : kDopInstances) {
    EXPECT_EQ(get(0x09, instance, 0x05), (ByteVec{0x8E, 0x01}));  // fault action: no change
    EXPECT_EQ(get(0x09, instance, 0x06), (ByteVec{0x8E, 0x00}));
    EXPECT_EQ(get(0x09, instance, 0x07), (ByteVec{0x8E, 0x01}));  // idle action: no change
    EXPECT_EQ(get(0x09, instance, 0x08), (ByteVec{0x8E, 0x00}));
  }
  EXPECT_EQ(get(0x0B, 0x01, 0x09), (ByteVec{0x8E, 0x00}));  // fault state: hold
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));  // idle state: hold
}

// The unsafe device going idle keeps the pump on, until a master writes an
// idle action of its own over the explicit connection.
TEST_F(Cdn127SlaveTest, UnsafeDeviceKeepsThePumpOnWhenIdleUntilToldOtherwise) {
  create(unsafe_options());
  boot();
  establish_poll();
  poll({0x05, 0x00, 0x34, 0x02});  // pump on, ballast on, 0x234
  ASSERT_TRUE(slave_->outputs().pump_on);

  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_idle, 1u);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);

  // DOP 1 Idle Action 0 (use the value), Idle Value 0 (Off).
  EXPECT_EQ(set(0x09, 0x01, 0x07, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x09, 0x01, 0x08, {0x00}), (ByteVec{0x90}));
  poll({0x05, 0x00, 0x34, 0x02});
  ASSERT_TRUE(slave_->outputs().pump_on);
  poll({});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // DOP 2 still holds
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_TRUE(slave_->pump().last_change_was_idle());
}

// A poll connection timing out (the fault condition): the unsafe device holds
// every output; once told to use its fault values, it takes them.
TEST_F(Cdn127SlaveTest, UnsafeDeviceHoldsOnPollTimeoutUntilGivenFaultValues) {
  create(unsafe_options());
  boot();
  establish_poll(100);
  poll({0x05, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());

  // DOP 1 Fault Action 0 with Fault Value 0; AOP Fault State 3 with Fault Value 500.
  EXPECT_EQ(set(0x09, 0x01, 0x05, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x09, 0x01, 0x06, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0B, {0xF4, 0x01}), (ByteVec{0x90}));
  EXPECT_EQ(request({0x05, 0x05, 0x02}), (ByteVec{0x85}));  // Connection Reset
  poll({0x05, 0x00, 0x34, 0x02});
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->outputs().n2_ballast_on);  // DOP 2 still holds
  EXPECT_EQ(slave_->outputs().analog_out_raw, 500);
}

// Identity Reset type 1 brings back the factory values, unsafe ones included.
TEST_F(Cdn127SlaveTest, FactoryResetRestoresTheUnsafeOutputActions) {
  create(unsafe_options());
  boot();
  allocate();
  EXPECT_EQ(set(0x09, 0x01, 0x07, {0x00}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x0B, 0x01, 0x0A, {0x01}), (ByteVec{0x90}));
  exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01, 0x01});
  advance(milliseconds(2001));
  allocate();
  EXPECT_EQ(get(0x09, 0x01, 0x07), (ByteVec{0x8E, 0x01}));
  EXPECT_EQ(get(0x0B, 0x01, 0x0A), (ByteVec{0x8E, 0x00}));
}

// ---------------------------------------------------------------------------
// Identity faults (Cdn127Device::set_faults, cdn127-sim's `fault` command)

TEST_F(Cdn127SlaveTest, IdentityFaultsShowInStatusAndState) {
  boot();
  allocate();
  auto& device = slave_->device();
  struct Case {
    IdentityFaults faults;
    ByteVec status;  // attribute 5, owned (bit 0) included
    std::uint8_t state;
    std::uint8_t supervisor;  // Device Supervisor attribute 11
  };
  const Case cases[] = {
      {{.minor_recoverable = true}, {0x01, 0x01}, 3, 2},
      {{.minor_unrecoverable = true}, {0x01, 0x02}, 3, 2},
      {{.major_recoverable = true}, {0x01, 0x04}, 4, 5},    // Abort
      {{.major_unrecoverable = true}, {0x01, 0x08}, 5, 6},  // Critical Fault
      {{.major_recoverable = true, .major_unrecoverable = true}, {0x01, 0x0C}, 5, 6},
  };
  for (const Case& c : cases) {
    device.set_faults(c.faults, now_);
    ByteVec status{0x8E};
    status.insert(status.end(), c.status.begin(), c.status.end());
    EXPECT_EQ(get(0x01, 0x01, 0x05), status) << hex(status);
    EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, c.state})) << hex(status);
    EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, c.supervisor})) << hex(status);
    device.set_faults({}, now_);
    EXPECT_EQ(get(0x01, 0x01, 0x05), (ByteVec{0x8E, 0x01, 0x00}));
    EXPECT_EQ(get(0x01, 0x01, 0x08), (ByteVec{0x8E, 0x03}));  // operating again
    EXPECT_EQ(get(0x32, 0x01, 0x0B), (ByteVec{0x8E, 0x02}));
  }
  // The short circuit of the minor recoverable fault is a DOP's Status too.
  device.set_faults({.minor_recoverable = true}, now_);
  EXPECT_EQ(get(0x09, 0x01, 0x04), (ByteVec{0x8E, 0x01}));
}

// A major fault applies the fault actions and holds the outputs there: polls
// are answered (the master still reads the inputs) but not applied, and
// output Sets are refused, until it clears.
TEST_F(Cdn127SlaveTest, MajorFaultAppliesTheFaultActionsAndHoldsTheOutputs) {
  boot();
  allocate();
  EXPECT_EQ(set(0x0B, 0x01, 0x09, {0x01}), (ByteVec{0x90}));  // AOP fault state: low
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  poll({0x05, 0x00, 0x34, 0x02});
  ASSERT_TRUE(slave_->outputs().pump_on);

  slave_->device().set_faults({.major_recoverable = true}, now_);
  EXPECT_FALSE(slave_->outputs().pump_on);  // fault value Off
  EXPECT_FALSE(slave_->outputs().n2_ballast_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());

  EXPECT_EQ(poll({0x05, 0x00, 0x34, 0x02}).size(), 6u);
  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_major_fault, 2u);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->pump().last_change_was_fault());
  EXPECT_EQ(set(0x09, 0x01, 0x03, {0x01}), error(0x10));  // device state conflict
  EXPECT_EQ(set(0x04, 0x05, 0x03, {0x01}), error(0x10));  // consumed assembly 5
  EXPECT_FALSE(slave_->outputs().pump_on);

  // A second major fault on top applies nothing new; clearing one leaves the
  // other in force.
  slave_->device().set_faults({.major_recoverable = true, .major_unrecoverable = true}, now_);
  slave_->device().set_faults({.major_unrecoverable = true}, now_);
  poll({0x05, 0x00, 0x34, 0x02});
  EXPECT_FALSE(slave_->outputs().pump_on);

  slave_->device().set_faults({}, now_);
  EXPECT_FALSE(slave_->outputs().pump_on);  // nothing is switched back on by itself
  poll({0x05, 0x00, 0x34, 0x02});
  EXPECT_TRUE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->outputs().analog_out_raw, 0x0234);
  EXPECT_EQ(slave_->counters().polls_major_fault, 3u);
}

// With the unsafe factory actions a major fault leaves the pump on: what
// the device was told to do on a fault.
TEST_F(Cdn127SlaveTest, MajorFaultOnAnUnsafeDeviceHoldsThePumpOn) {
  create(unsafe_options());
  boot();
  establish_poll();
  poll({0x01, 0x00, 0x00, 0x00});
  slave_->device().set_faults({.major_recoverable = true}, now_);
  EXPECT_TRUE(slave_->outputs().pump_on);
  poll({});  // idle actions held off too
  EXPECT_TRUE(slave_->outputs().pump_on);
}

// Minor faults change no output.
TEST_F(Cdn127SlaveTest, MinorFaultsLeaveTheOutputsToTheMaster) {
  boot();
  establish_poll();
  poll({0x01, 0x00, 0x00, 0x00});
  slave_->device().set_faults({.minor_recoverable = true, .minor_unrecoverable = true}, now_);
  EXPECT_TRUE(slave_->outputs().pump_on);
  poll({0x00, 0x00, 0x00, 0x00});
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_EQ(slave_->counters().polls_major_fault, 0u);
}

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

// ---------------------------------------------------------------------------
// Readings of the manual that field devices took (SlaveOptions): each on,
// what the wire shows; each off, what it showed before.

// Configuration NOTE 1 read strictly: refused while the poll connection
// exists, Configuring and Timed Out included, not only while Established.
TEST_F(Cdn127SlaveTest, ConfigurationLockedWhilePollAllocated) {
  SlaveOptions o = default_options();
  o.configuration_locked_while_poll_allocated = true;
  create(o);
  boot();
  allocate();  // explicit + poll: the poll connection is Configuring
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kConfiguring);
  EXPECT_EQ(set(0x40, 0x01, 0x01, {0x81}), error(0x0C));      // Mode
  EXPECT_EQ(set(0x40, 0x01, 0x02, {0x07}), error(0x0C));      // Number DIP
  EXPECT_EQ(set(0x40, 0x01, 0x03, {0x02}), error(0x0C));      // Number DOP
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), error(0x0C));      // Number AIP
  EXPECT_EQ(set(0x40, 0x01, 0x05, {0x00}), error(0x0C));      // Number AOP
  EXPECT_EQ(set(0x40, 0x01, 0x0A, {0x01}), error(0x0C));      // NoNcMask
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), error(0x0C));  // Reset to the CDN118 preset
  EXPECT_EQ(get(0x40, 0x01, 0x04), (ByteVec{0x8E, 0x02}));    // unchanged
  EXPECT_EQ(get(0x40, 0x01, 0x01), (ByteVec{0x8E, 0x86}));

  // Timed Out (the explicit connection still fed): still allocated, still refused.
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), error(0x0C));

  // Released: accepted.
  EXPECT_EQ(single(kUnconnectedId, {kMaster, 0x4C, 0x03, 0x01, 0x02}), (ByteVec{kMaster, 0xCC}));
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), (ByteVec{0x90}));
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
}

TEST_F(Cdn127SlaveTest, ConfigurationLockedOnlyWhileEstablishedWithoutTheOption) {
  boot();
  allocate();
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x01}), (ByteVec{0x90}));  // Configuring: accepted
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x02}), error(0x0C));  // Established: refused
  advance(milliseconds(400));
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kTimedOut);
  EXPECT_EQ(set(0x40, 0x01, 0x04, {0x02}), (ByteVec{0x90}));  // Timed Out: accepted
}

// Attributes 14/16 Get only, as the Connection table lists them.
TEST_F(Cdn127SlaveTest, PollPathsFixed) {
  SlaveOptions o = default_options();
  o.poll_paths_fixed = true;
  create(o);
  boot();
  allocate();
  // produced path: class 4, instance 103, attribute 3; consumed: instance 104
  const ByteVec produced{0x8E, 0x20, 0x04, 0x24, 0x67, 0x30, 0x03};
  const ByteVec consumed{0x8E, 0x20, 0x04, 0x24, 0x68, 0x30, 0x03};
  EXPECT_EQ(get(0x05, 0x02, 0x0E), produced);
  EXPECT_EQ(get(0x05, 0x02, 0x10), consumed);
  // Configuring: not settable, whatever the path (a valid one, the 16-bit
  // form in fragments, garbage).
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x02, 0x30, 0x03}), error(0x0E));
  EXPECT_EQ(request({0x10, 0x05, 0x02, 0x10, 0x21, 0x04, 0x00, 0x25, 0x64, 0x00, 0x30, 0x03}),
            error(0x0E));
  EXPECT_EQ(set(0x05, 0x02, 0x10, {0xFF}), error(0x0E));
  EXPECT_EQ(get(0x05, 0x02, 0x0E), produced);
  EXPECT_EQ(get(0x05, 0x02, 0x10), consumed);
  // The formats of 103/104 follow the Configuration object (CDN118 preset).
  EXPECT_EQ(request({0x05, 0x40, 0x01, 0x01}), (ByteVec{0x85}));
  EXPECT_EQ(get(0x05, 0x02, 0x07), (ByteVec{0x8E, 0x02, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x08), (ByteVec{0x8E, 0x03, 0x00}));
  // Established: 0x0E still (not 0x0C), the paths in force unchanged.
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x67, 0x30, 0x03}), error(0x0E));
  EXPECT_EQ(set(0x05, 0x02, 0x10, {0x20, 0x04, 0x24, 0x68, 0x30, 0x03}), error(0x0E));
  EXPECT_EQ(get(0x05, 0x02, 0x0E), produced);
  EXPECT_EQ(get(0x05, 0x02, 0x10), consumed);
  EXPECT_EQ(poll({0x01, 0xFF, 0x0F}), (ByteVec{0x80, 0x1E}));
}

TEST_F(Cdn127SlaveTest, PollPathsSettableWhileConfiguringWithoutTheOption) {
  boot();
  allocate();
  EXPECT_EQ(get(0x05, 0x02, 0x0E), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x67, 0x30, 0x03}));
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x68, 0x30, 0x03}));
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x02, 0x30, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(set(0x05, 0x02, 0x10, {0x20, 0x04, 0x24, 0x64, 0x30, 0x03}), (ByteVec{0x90}));
  EXPECT_EQ(get(0x05, 0x02, 0x0E), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x02, 0x30, 0x03}));
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x64, 0x30, 0x03}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x64, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x0E, {0x20, 0x04, 0x24, 0x67, 0x30, 0x03}), error(0x0C));
}

TEST_F(Cdn127SlaveTest, IdlePollAnsweredEmpty) {
  SlaveOptions o = default_options();
  o.idle_poll_answered_empty = true;
  create(o);
  boot();
  establish_poll();
  EXPECT_EQ(poll({0x05, 0x00, 0x00, 0x08}).size(), 6u);
  ASSERT_TRUE(slave_->outputs().pump_on);
  // 0-byte poll: idle actions (pump off: idle value 0), answered with 0 bytes.
  auto out = exchange(kPollId, {});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "3C3:");
  EXPECT_EQ(out[0].len, 0u);
  EXPECT_FALSE(slave_->outputs().pump_on);
  EXPECT_TRUE(slave_->pump().last_change_was_idle());
  // A short, non-empty poll is idle too.
  EXPECT_EQ(poll({0x01}), ByteVec{});
  EXPECT_EQ(slave_->counters().polls_idle, 2u);
  // A full poll is answered in full again.
  EXPECT_EQ(poll({0x01, 0x00, 0x00, 0x00}).size(), 6u);
  EXPECT_TRUE(slave_->outputs().pump_on);
}

TEST_F(Cdn127SlaveTest, IdlePollAnsweredInFullWithoutTheOption) {
  boot();
  establish_poll();
  EXPECT_EQ(poll({}).size(), 6u);
  EXPECT_EQ(poll({0x01}).size(), 6u);
  EXPECT_EQ(slave_->counters().polls_idle, 2u);
}

// The 12-byte Set of the consumed path (16-bit form) in three fragments,
// 5 + 5 + 2 bytes:
//   8A 00 | 10 05 02 10 21      first, count 0
//   8A 41 | 04 00 25 64 00      middle, count 1
//   8A 82 | 30 03               last, count 2
TEST_F(Cdn127SlaveTest, NoAckOfLastRequestFragment) {
  SlaveOptions o = default_options();
  o.no_ack_of_last_request_fragment = true;
  create(o);
  boot();
  allocate();
  auto out = exchange(kRequestId, {0x8A, 0x00, 0x10, 0x05, 0x02, 0x10, 0x21});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C0 00");
  out = exchange(kRequestId, {0x8A, 0x41, 0x04, 0x00, 0x25, 0x64, 0x00});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C1 00");
  // The last: the response alone, no ack before it.
  out = exchange(kRequestId, {0x8A, 0x82, 0x30, 0x03});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 90");
  // The last fragment again: neither acked nor executed twice.
  EXPECT_TRUE(exchange(kRequestId, {0x8A, 0x82, 0x30, 0x03}).empty());
  EXPECT_EQ(slave_->counters().explicit_requests, 1u);
  EXPECT_EQ(get(0x05, 0x02, 0x10), (ByteVec{0x8E, 0x20, 0x04, 0x24, 0x64, 0x30, 0x03}));
}

TEST_F(Cdn127SlaveTest, LastRequestFragmentAckedWithoutTheOption) {
  boot();
  allocate();
  EXPECT_EQ(exchange(kRequestId, {0x8A, 0x00, 0x10, 0x05, 0x02, 0x10, 0x21}).size(), 1u);
  EXPECT_EQ(exchange(kRequestId, {0x8A, 0x41, 0x04, 0x00, 0x25, 0x64, 0x00}).size(), 1u);
  auto out = exchange(kRequestId, {0x8A, 0x82, 0x30, 0x03});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C2 00");
  EXPECT_EQ(hex(out[1]), "41B: 0A 90");
  // Its ack lost: the repeat is acked again, not executed twice.
  out = exchange(kRequestId, {0x8A, 0x82, 0x30, 0x03});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C2 00");
  EXPECT_EQ(slave_->counters().explicit_requests, 1u);
}

// A slow device: what it answers, measured on the fake clock.
TEST_F(Cdn127SlaveTest, ExplicitResponseDelay) {
  SlaveOptions o = default_options();
  o.explicit_response_delay = milliseconds(300);
  create(o);
  boot();
  // Allocate on the unconnected port: done at once, answered 300 ms later.
  EXPECT_TRUE(exchange(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster}).empty());
  EXPECT_EQ(slave_->owner(), kMaster);
  advance(milliseconds(299));
  EXPECT_TRUE(sink_.take().empty());
  advance(milliseconds(1));
  auto out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 0A CB 00");

  // Two requests 10 ms apart (a success and an error): answered in order,
  // each 300 ms after its own.
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x01}).empty());
  advance(milliseconds(10));
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x0A}).empty());
  advance(milliseconds(289));
  EXPECT_TRUE(sink_.take().empty());
  advance(milliseconds(1));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 8E 3B 00");
  advance(milliseconds(9));
  EXPECT_TRUE(sink_.take().empty());
  advance(milliseconds(1));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 94 14 FF");

  // A fragmented response: its first fragment late, the next one on the ack.
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x07}).empty());
  advance(milliseconds(300));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A 00 8E 06 43 44 4E 31");
  out = exchange(kRequestId, {0x8A, 0xC0, 0x00});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A 81 32 37");
  EXPECT_TRUE(exchange(kRequestId, {0x8A, 0xC1, 0x00}).empty());

  // A fragmented request: fragment acks at once, the response late.
  out = exchange(kRequestId, {0x8A, 0x00, 0x10, 0x05, 0x02, 0x10, 0x21});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C0 00");
  out = exchange(kRequestId, {0x8A, 0x41, 0x04, 0x00, 0x25, 0x64, 0x00});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C1 00");
  out = exchange(kRequestId, {0x8A, 0x82, 0x30, 0x03});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C2 00");
  advance(milliseconds(300));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 90");

  // Identity Reset: the restart waits for its late response.
  EXPECT_TRUE(exchange(kRequestId, {kMaster, 0x05, 0x01, 0x01}).empty());
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kOnline);
  advance(milliseconds(300));
  out = sink_.take();
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(hex(out[0]), "41B: 0A 85");
  EXPECT_EQ(out[1].id, kDupMacId);
  EXPECT_EQ(slave_->network_state(), Cdn127Slave::NetworkState::kDuplicateMacCheck);
}

TEST_F(Cdn127SlaveTest, PollResponseDelay) {
  SlaveOptions o = default_options();
  o.poll_response_delay = milliseconds(3);
  create(o);
  boot();
  establish_poll();  // explicit responses are not delayed
  ASSERT_TRUE(slave_->pump().set_analog_input(0, 0x0123));
  // The outputs change on arrival; the response comes 3 ms later.
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  EXPECT_TRUE(slave_->outputs().pump_on);
  advance(milliseconds(1));
  // A second poll 1 ms later, with another analog input: answered after the first.
  ASSERT_TRUE(slave_->pump().set_analog_input(0, 0x0456));
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  advance(milliseconds(1));
  EXPECT_TRUE(sink_.take().empty());
  advance(milliseconds(1));
  auto out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "3C3: 80 1E 23 01 00 00");
  advance(milliseconds(1));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "3C3: 80 1E 56 04 00 00");
  // A power cycle drops what is still queued.
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  slave_->power_cycle(now_);
  sink_.take();
  advance(milliseconds(10));
  for (const auto& f : sink_.take()) EXPECT_NE(f.id, kPollResponseId);
}

// Every reading at once (what cdn127-sim --reading field runs), as a master
// meets it from Allocate to the first polls.
TEST_F(Cdn127SlaveTest, FieldReadingAllOptionsTogether) {
  SlaveOptions o = default_options();
  apply_field_reading(o);
  create(o);
  boot();
  // Answers 300 ms late, explicit and unconnected alike.
  auto late = [this](std::uint32_t id, const ByteVec& data) {
    EXPECT_TRUE(exchange(id, data).empty());
    advance(milliseconds(299));
    EXPECT_TRUE(sink_.take().empty());
    advance(milliseconds(1));
    auto out = sink_.take();
    EXPECT_EQ(out.size(), 1u);
    return out.empty() ? std::string() : hex(out[0]);
  };
  EXPECT_EQ(late(kUnconnectedId, {kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster}), "41B: 0A CB 00");
  EXPECT_EQ(late(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x06}),
            "41B: 0A 8E 34 12");  // UINT serial
  EXPECT_EQ(late(kRequestId, {kMaster, 0x0E, 0x01, 0x01, 0x08}), "41B: 0A 94 14 FF");  // no State
  // Configuring: configuration locked, paths fixed.
  EXPECT_EQ(late(kRequestId, {kMaster, 0x10, 0x40, 0x01, 0x04, 0x01}), "41B: 0A 94 0C FF");
  EXPECT_EQ(late(kRequestId, {kMaster, 0x05, 0x40, 0x01, 0x01}), "41B: 0A 94 0C FF");
  EXPECT_EQ(late(kRequestId, {kMaster, 0x0E, 0x05, 0x02, 0x0E}), "41B: 0A 8E 20 04 24 67 30 03");
  // The fragmented Set of the consumed path: first acked, last not, the
  // refusal 300 ms after it.
  auto out = exchange(kRequestId, {0x8A, 0x00, 0x10, 0x05, 0x02, 0x10, 0x21, 0x04});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "41B: 8A C0 00");
  EXPECT_EQ(late(kRequestId, {0x8A, 0x81, 0x00, 0x25, 0x64, 0x00, 0x30, 0x03}), "41B: 0A 94 0E FF");
  // EPR 150 ms kept as 200 (steps of 100 ms), said in the response.
  EXPECT_EQ(late(kRequestId, {kMaster, 0x10, 0x05, 0x02, 0x09, 0x96, 0x00}), "41B: 0A 90 C8 00");
  ASSERT_EQ(slave_->poll_state(), ConnectionState::kEstablished);
  // Polls answered 3 ms late; an idle poll with nothing.
  EXPECT_TRUE(exchange(kPollId, {0x01, 0x00, 0x00, 0x00}).empty());
  advance(milliseconds(3));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].len, 6u);
  EXPECT_TRUE(exchange(kPollId, {}).empty());
  EXPECT_FALSE(slave_->outputs().pump_on);
  advance(milliseconds(2));
  EXPECT_TRUE(sink_.take().empty());
  advance(milliseconds(1));
  out = sink_.take();
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(hex(out[0]), "3C3:");
}

// Options that were there before, as a strict device has them.
TEST_F(Cdn127SlaveTest, NoIdentityStateAndCoarseTimerResolution) {
  SlaveOptions o = default_options();
  o.unsupported_attributes = {{0x01, 8}};
  o.timer_resolution = milliseconds(100);
  create(o);
  boot();
  allocate();
  EXPECT_EQ(get(0x01, 0x01, 0x08), error(0x14));
  EXPECT_EQ(get(0x01, 0x01, 0x06), (ByteVec{0x8E, 0x34, 0x12}));  // UINT by default
  // Set answers the rate kept: 150 -> 200, 200 -> 200, 1 -> 100.
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x96, 0x00}), (ByteVec{0x90, 0xC8, 0x00}));
  EXPECT_EQ(get(0x05, 0x02, 0x09), (ByteVec{0x8E, 0xC8, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0xC8, 0x00}), (ByteVec{0x90, 0xC8, 0x00}));
  EXPECT_EQ(set(0x05, 0x02, 0x09, {0x01, 0x00}), (ByteVec{0x90, 0x64, 0x00}));
  EXPECT_EQ(set(0x05, 0x01, 0x09, {0xC4, 0x09}), (ByteVec{0x90, 0xC4, 0x09}));  // 2500 stays
}

// ---------------------------------------------------------------------------
// Pump model

TEST(PumpModel, RunningFollowsPumpOnAfterSpinUpAndSpinDown) {
  PumpModel::Config c;
  c.spin_up = seconds(3);
  c.spin_down = seconds(5);
  PumpModel pump(c);
  TimePoint t{};
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  EXPECT_EQ(pump.next_deadline(), t + seconds(3));
  pump.advance(t + milliseconds(2999));
  EXPECT_FALSE(pump.running());
  pump.advance(t + seconds(3));
  EXPECT_TRUE(pump.running());
  pump.set_outputs({}, OutputCause::kPoll, t + seconds(10));
  pump.advance(t + milliseconds(14999));
  EXPECT_TRUE(pump.running());
  EXPECT_EQ(pump.motor(), PumpModel::Motor::kStopping);
  pump.advance(t + seconds(15));
  EXPECT_FALSE(pump.running());
  EXPECT_EQ(pump.next_deadline(), kNever);
}

TEST(PumpModel, SwitchedOffBeforeSpeedNeverRuns) {
  PumpModel pump;
  TimePoint t{};
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  pump.set_outputs({}, OutputCause::kPoll, t + seconds(1));
  pump.advance(t + seconds(10));
  EXPECT_FALSE(pump.running());
}

TEST(PumpModel, InterlockAndAlarmStopThePump) {
  PumpModel::Config c;
  c.spin_up = Duration::zero();
  c.spin_down = Duration::zero();
  PumpModel pump(c);
  TimePoint t{};
  pump.set_interlock_ok(false, t);
  pump.set_outputs({.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 0},
                   OutputCause::kPoll, t);
  EXPECT_FALSE(pump.running());
  pump.set_interlock_ok(true, t);
  EXPECT_TRUE(pump.running());
  pump.set_alarm(true, t);
  EXPECT_FALSE(pump.running());
  EXPECT_TRUE(pump.inputs().alarm_active);
  EXPECT_FALSE(pump.set_analog_input(0, 4096));
  EXPECT_FALSE(pump.set_analog_input(2, 1));
}

TEST(PumpModel, ExceptionStatusGatedByEnables) {
  PumpModel pump;
  TimePoint t{};
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x00);
  pump.set_interlock_ok(false, t);
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x02);
  EXPECT_EQ(pump.exception_status(false, true).encode(), 0x00);
  pump.set_interlock_ok(true, t);
  pump.set_warning(true);
  EXPECT_EQ(pump.exception_status(true, true).encode(), 0x20);
  EXPECT_EQ(pump.exception_status(true, false).encode(), 0x00);
}

}  // namespace
}  // namespace dnbridge::sim
