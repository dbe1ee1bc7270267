#pragma once
// Shared set-up for the simulated CDN127's tests (cdn127_slave_*_test.cpp):
// the slave driven frame by frame with a fake clock, the fixture playing the
// master's side of the wire. Slave MAC 3, master MAC 10 unless a test says
// otherwise:
//   0x41B explicit/unconnected response   0x41C explicit request
//   0x41D poll command                    0x41E Allocate/Release
//   0x41F duplicate MAC check             0x3C3 poll response
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "support/bytes.hpp"
#include "support/sim_slave_driver.hpp"

namespace dnbridge::sim {

using test::ByteVec;
using test::frame;
using test::hex;

inline constexpr std::uint32_t kResponseId = 0x41B;
inline constexpr std::uint32_t kRequestId = 0x41C;
inline constexpr std::uint32_t kPollId = 0x41D;
inline constexpr std::uint32_t kUnconnectedId = 0x41E;
inline constexpr std::uint32_t kDupMacId = 0x41F;
inline constexpr std::uint32_t kPollResponseId = 0x3C3;
inline constexpr std::uint8_t kMaster = 10;  // 0x0A

using test::RecordingSink;

inline can::CanFrame make(std::uint32_t id, const ByteVec& data) {
  return can::CanFrame::make(id, Bytes(data.data(), data.size())).value();
}

inline ByteVec bytes_of(const can::CanFrame& f) {
  return ByteVec(f.data.begin(), f.data.begin() + f.len);
}

inline SlaveOptions default_options() {
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

// A device that leaves the factory with kUnsafeFactoryOutputActions (every
// output held on a fault and on idle; SlaveOptions::factory_output_actions),
// and the DOP instances those actions are read and written on.
inline constexpr std::uint8_t kDopInstances[] = {1, 2};  // Pump On, N2 Ballast On

inline SlaveOptions unsafe_options() {
  SlaveOptions o = default_options();
  o.factory_output_actions = kUnsafeFactoryOutputActions;
  return o;
}

}  // namespace dnbridge::sim
