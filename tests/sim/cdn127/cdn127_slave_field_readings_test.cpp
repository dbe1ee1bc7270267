// The simulated CDN127 on the wire, frame by frame with a fake clock
// (cdn127_slave_fixture.hpp): the readings of the manual that field devices
// took (SlaveOptions), each on and off: configuration locked, fixed poll
// paths, idle polls answered empty, the last request fragment not acked,
// response delays, no Identity State and a coarse timer resolution.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "sim/cdn127/cdn127_slave_fixture.hpp"

namespace dnbridge::sim {
namespace {

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

}  // namespace
}  // namespace dnbridge::sim
