// The start-up of one node on the wire, frame by frame, against a device
// scripted here: every request the life-cycle table (node_lifecycle.cpp)
// makes and every kind of answer it takes, as golden frames annotated field
// by field. The device is a CDN127 whose E2 holds the CDN118 preset (so the
// master has the configuration to write), that refuses a Configuration Set
// while it believes a poll connection exists, has no Identity State, answers
// a fragmented request without acknowledging its last fragment, rounds the
// expected packet rate up to 100 ms and answers idle polls with no data.
//
// Identifiers, node MAC 12 (0x0C), master MAC 0 (CAN id = 0x400 | MAC << 3 |
// message for Group 2; 0x3C0 | MAC for Group 1 message 15):
//   466 unconnected request (Allocate, Release)   464 explicit request
//   463 explicit response                          465 poll command
//   3CC poll response                              407 the master's duplicate MAC check
// Explicit header byte: [Frag | XID | MAC 0]; XID toggles with each new
// transaction (40 = XID 1, 00 = XID 0), and the device echoes it.
#include <gtest/gtest.h>

#include <cstdio>
#include <deque>
#include <sstream>
#include <string>

#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::devicenet {
namespace {

MacId mac(unsigned v) { return MacId::from(v).value(); }

std::string hex(const can::CanFrame& f) {
  std::string s;
  char buf[8];
  std::snprintf(buf, sizeof buf, "%03X:", static_cast<unsigned>(f.id));
  s += buf;
  for (std::size_t i = 0; i < f.len; ++i) {
    std::snprintf(buf, sizeof buf, " %02X", f.data[i]);
    s += buf;
  }
  return s;
}

can::CanFrame parse(const std::string& text) {
  std::istringstream in(text);
  can::CanFrame f;
  std::string id;
  in >> id;
  f.id = static_cast<std::uint32_t>(std::stoul(id.substr(0, id.size() - 1), nullptr, 16));
  for (std::string byte; in >> byte;) {
    f.data[f.len++] = static_cast<std::uint8_t>(std::stoul(byte, nullptr, 16));
  }
  return f;
}

class RecordingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint) override { frames.push_back(frame); }
  std::deque<can::CanFrame> frames;
};

class States final : public ScannerObserver {
 public:
  void on_node_state(MacId, NodeState, NodeState to, const std::string& reason,
                     TimePoint) override {
    last = to;
    last_reason = reason;
  }
  NodeState last = NodeState::kAbsent;
  std::string last_reason;
};

class NodeStartup : public ::testing::Test {
 protected:
  NodeStartup() {
    ScannerConfig c;
    c.master_mac = mac(0);
    NodeConfig n;
    n.mac = mac(12);
    n.name = "pump";
    n.poll_period = milliseconds(100);
    n.expected_packet_rate = milliseconds(250);
    n.profile = profiles::cdn127::make_node_profile(
                    profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127),
                    profiles::cdn127::SafeStateConfig{})
                    .value();
    c.nodes.push_back(n);
    scanner_.emplace(c, sink_, states_, Logger());
  }

  void run_timers() {
    while (scanner_->next_deadline() <= now_) scanner_->on_timer(now_);
  }
  // The master's next frame.
  std::string sent() {
    if (sink_.frames.empty()) return "(nothing sent)";
    const can::CanFrame f = sink_.frames.front();
    sink_.frames.pop_front();
    return hex(f);
  }
  // The device's answer, 1 ms later.
  void answer(const std::string& frame) {
    now_ += milliseconds(1);
    scanner_->on_frame(parse(frame), now_);
    run_timers();
  }
  const Node& node() const { return *scanner_->node(mac(12)); }

  RecordingSink sink_;
  States states_;
  std::optional<Scanner> scanner_;
  TimePoint now_ = TimePoint{} + seconds(100);
};

TEST_F(NodeStartup, EveryRequestAndAnswerOnTheWire) {
  scanner_->start(now_);
  // Duplicate MAC ID request for MAC 0: [port 0][vendor 0][serial 0].
  EXPECT_EQ(sent(), "407: 00 00 00 00 00 00 00");
  now_ = scanner_->next_deadline();
  run_timers();
  EXPECT_EQ(sent(), "407: 00 00 00 00 00 00 00");  // the second, a second later
  now_ = scanner_->next_deadline();
  run_timers();
  ASSERT_EQ(scanner_->state(), PortState::kRunning);

  // 1. Allocate: [40 hdr][4B Allocate][03 DeviceNet class][01 instance]
  //    [01 choice: explicit only][00 allocator MAC].
  EXPECT_EQ(sent(), "466: 40 4B 03 01 01 00");
  answer("463: 40 CB 00");  // [hdr][CB Allocate response][00 body format 8/8]
  EXPECT_EQ(states_.last, NodeState::kIdentifying);

  // 2. Get DeviceNet.AllocationInformation: [0E Get][03][01][05 attribute].
  EXPECT_EQ(sent(), "464: 00 0E 03 01 05");
  answer("463: 00 8E 01 00");  // [8E Get response][01 choice: explicit][00 master]

  // 3. Identity (class 01): vendor, product type, product code.
  EXPECT_EQ(sent(), "464: 40 0E 01 01 01");
  answer("463: 40 8E 3B 00");  // vendor 59
  EXPECT_EQ(sent(), "464: 00 0E 01 01 02");
  answer("463: 00 8E 1B 00");  // product type 27
  EXPECT_EQ(sent(), "464: 40 0E 01 01 03");
  answer("463: 40 8E 60 07");  // product code 1888
  // 4. Revision, serial number (UINT, 2 bytes), name, status, state.
  EXPECT_EQ(sent(), "464: 00 0E 01 01 04");
  answer("463: 00 8E 01 05");  // revision 1.5
  EXPECT_EQ(sent(), "464: 40 0E 01 01 06");
  answer("463: 40 8E 34 12");  // serial 0x1234, as the manual types it
  EXPECT_EQ(sent(), "464: 00 0E 01 01 07");
  answer("463: 00 8E 03 43 44 4E");  // SHORT_STRING "CDN"
  EXPECT_EQ(sent(), "464: 40 0E 01 01 05");
  answer("463: 40 8E 01 00");  // status 0x0001: owned
  EXPECT_EQ(sent(), "464: 00 0E 01 01 08");
  answer("463: 00 94 14 FF");  // [94 error response][14 attribute not supported][FF]
  EXPECT_EQ(node().identity().serial_number, 0x1234u);
  EXPECT_EQ(node().identity().status, std::uint16_t{1});
  EXPECT_FALSE(node().identity().state.has_value()) << "state unknown, not a fault";
  EXPECT_EQ(states_.last, NodeState::kConfiguring);

  // 5-7. Configuration (class 40): Mode read, differs (81, the CDN118's),
  // written (86), read back.
  EXPECT_EQ(sent(), "464: 40 0E 40 01 01");
  answer("463: 40 8E 81");
  EXPECT_EQ(sent(), "464: 00 10 40 01 01 86");  // [10 Set][40][01][01 Mode][86]
  answer("463: 00 90");                         // [90 Set response]
  EXPECT_EQ(sent(), "464: 40 0E 40 01 01");
  answer("463: 40 8E 86");
  // Digital inputs and outputs already right: read only.
  EXPECT_EQ(sent(), "464: 00 0E 40 01 02");
  answer("463: 00 8E 08");
  EXPECT_EQ(sent(), "464: 40 0E 40 01 03");
  answer("463: 40 8E 08");
  // Analog inputs 0, 2 wanted; the device refuses: object state conflict.
  EXPECT_EQ(sent(), "464: 00 0E 40 01 04");
  answer("463: 00 8E 00");
  EXPECT_EQ(sent(), "464: 40 10 40 01 04 02");
  answer("463: 40 94 0C FF");  // [0C object state conflict]
  // The poll connection released ([4C Release][03][01][02 poll]), after an
  // idle poll in case it is one left from before, carrying outputs; the
  // device had none (no answer to the poll; [0B already in requested
  // mode][02 invalid choice] to the Release).
  EXPECT_EQ(sent(), "465:");
  EXPECT_EQ(sent(), "466: 00 4C 03 01 02");
  answer("463: 00 94 0B 02");
  EXPECT_EQ(sent(), "464: 40 10 40 01 04 02");  // the Set once more
  answer("463: 40 90");
  EXPECT_EQ(sent(), "464: 00 0E 40 01 04");
  answer("463: 00 8E 02");
  EXPECT_EQ(sent(), "464: 40 0E 40 01 05");  // analog outputs
  answer("463: 40 8E 01");
  EXPECT_EQ(sent(), "464: 00 0E 40 01 0A");  // NoNcMask
  answer("463: 00 8E 00");
  EXPECT_EQ(node().counters().settings_written, 2u);

  // 7b. The safe state, off on fault and on idle (the default), before any
  // poll connection: each output's value first, then its action. DOP
  // (class 09) instance 1, the pump: fault value (06) off, fault action (05)
  // "use the value": as wanted.
  EXPECT_EQ(sent(), "464: 40 0E 09 01 06");
  answer("463: 40 8E 00");
  EXPECT_EQ(sent(), "464: 00 0E 09 01 05");
  answer("463: 00 8E 00");
  // Idle value (08) off; idle action (07) "no change", an unsafe factory
  // setting: set to "use the value" and read back.
  EXPECT_EQ(sent(), "464: 40 0E 09 01 08");
  answer("463: 40 8E 00");
  EXPECT_EQ(sent(), "464: 00 0E 09 01 07");
  answer("463: 00 8E 01");
  EXPECT_EQ(sent(), "464: 40 10 09 01 07 00");
  answer("463: 40 90");
  EXPECT_EQ(sent(), "464: 00 0E 09 01 07");
  answer("463: 00 8E 00");
  // DOP instance 2, the N2 ballast: as wanted.
  EXPECT_EQ(sent(), "464: 40 0E 09 02 06");
  answer("463: 40 8E 00");
  EXPECT_EQ(sent(), "464: 00 0E 09 02 05");
  answer("463: 00 8E 00");
  EXPECT_EQ(sent(), "464: 40 0E 09 02 08");
  answer("463: 40 8E 00");
  EXPECT_EQ(sent(), "464: 00 0E 09 02 07");
  answer("463: 00 8E 00");
  // AOP (class 0B) instance 1: fault value (0B) 0, fault state (09) 0
  // "hold the last value": set to 3, "the fault value".
  EXPECT_EQ(sent(), "464: 40 0E 0B 01 0B");
  answer("463: 40 8E 00 00");
  EXPECT_EQ(sent(), "464: 00 0E 0B 01 09");
  answer("463: 00 8E 00");
  EXPECT_EQ(sent(), "464: 40 10 0B 01 09 03");
  answer("463: 40 90");
  EXPECT_EQ(sent(), "464: 00 0E 0B 01 09");
  answer("463: 00 8E 03");
  // Idle value (0C) 0, idle state (0A) hold: set to 3 likewise.
  EXPECT_EQ(sent(), "464: 40 0E 0B 01 0C");
  answer("463: 40 8E 00 00");
  EXPECT_EQ(sent(), "464: 00 0E 0B 01 0A");
  answer("463: 00 8E 00");
  EXPECT_EQ(sent(), "464: 40 10 0B 01 0A 03");
  answer("463: 40 90");
  EXPECT_EQ(sent(), "464: 00 0E 0B 01 0A");
  answer("463: 00 8E 03");
  EXPECT_EQ(node().counters().settings_written, 5u);

  // 8. Allocate the poll connection: [02 choice: poll].
  EXPECT_EQ(sent(), "466: 40 4B 03 01 02 00");
  answer("463: 40 CB 00");

  // 9. Connection 2 paths: produced (attribute 0E) as wanted, assembly 103
  // (20 04 class 4 | 24 67 instance 103 | 30 03 attribute 3).
  EXPECT_EQ(sent(), "464: 00 0E 05 02 0E");
  answer("463: 00 8E 20 04 24 67 30 03");
  // Consumed (attribute 10): the device has assembly 100; 104 wanted.
  EXPECT_EQ(sent(), "464: 40 0E 05 02 10");
  answer("463: 40 8E 20 04 24 64 30 03");
  // The Set is 10 bytes of message: two fragments. [80 hdr: Frag, XID 0,
  // MAC 0][00 first fragment, count 0][10 05 02 10 20 04].
  EXPECT_EQ(sent(), "464: 80 00 10 05 02 10 20 04");
  answer("463: 80 C0 00");                      // [80 hdr][C0 ack, count 0][00 success]
  EXPECT_EQ(sent(), "464: 80 81 24 68 30 03");  // [81 last, count 1][24 68 30 03]
  answer("463: 00 90");  // the response, without the ack of the last fragment
  EXPECT_EQ(node().explicit_counters().responses_before_final_ack, 1u);

  // 10. Sizes: Connection 2 attributes 7 and 8.
  EXPECT_EQ(states_.last, NodeState::kVerifying);
  EXPECT_EQ(sent(), "464: 40 0E 05 02 07");
  answer("463: 40 8E 06 00");  // produces 6 bytes
  EXPECT_EQ(sent(), "464: 00 0E 05 02 08");
  answer("463: 00 8E 04 00");  // consumes 4 bytes

  // 11. Expected packet rates: explicit (Connection 1) 2500 ms, poll 250 ms,
  // which the device keeps as 300 (C4 09 = 2500, FA 00 = 250, 2C 01 = 300).
  EXPECT_EQ(sent(), "464: 40 10 05 01 09 C4 09");
  answer("463: 40 90 C4 09");
  EXPECT_EQ(sent(), "464: 00 10 05 02 09 FA 00");
  answer("463: 00 90 2C 01");

  // 12. Online: the first poll, idle (no commander yet): zero length.
  EXPECT_EQ(states_.last, NodeState::kOnline) << states_.last_reason;
  EXPECT_EQ(node().poll_epr(), milliseconds(300));
  EXPECT_EQ(sent(), "465:");
  answer("3CC:");  // answered with no data: valid for an idle poll
  EXPECT_EQ(node().counters().idle_empty_responses, 1u);
  EXPECT_EQ(node().counters().errors, 0u);
  EXPECT_EQ(sent(), "(nothing sent)");
  EXPECT_EQ(node().counters().allocate_attempts, 1u);

  // 13. Shutdown: an idle poll, then Release of both connections. A device
  // that no longer has one of them refuses the Release whole (0x0B): each
  // connection is then released alone, the poll connection first.
  scanner_->stop(now_);
  EXPECT_EQ(sent(), "465:");
  answer("3CC:");
  EXPECT_EQ(sent(), "466: 40 4C 03 01 03");  // [4C Release][03][01][03 explicit + poll]
  answer("463: 40 94 0B 02");                // already in the requested state
  EXPECT_EQ(sent(), "466: 00 4C 03 01 02");  // the poll connection alone
  answer("463: 00 94 0B 02");                // which it had not
  EXPECT_EQ(sent(), "466: 40 4C 03 01 01");  // the explicit connection alone
  answer("463: 40 CC");
  EXPECT_EQ(sent(), "(nothing sent)");
  EXPECT_EQ(states_.last, NodeState::kStopped) << states_.last_reason;
}

// A poll connection still allocated from before (this master restarted, or
// lost the bus, within the device's own timeout) may still carry the outputs
// last commanded: it is polled idle before it is released, and the answer to
// that poll is not taken for an error.
TEST_F(NodeStartup, APollConnectionLeftFromBeforeIsPolledIdleBeforeItsRelease) {
  scanner_->start(now_);
  EXPECT_EQ(sent(), "407: 00 00 00 00 00 00 00");
  now_ = scanner_->next_deadline();
  run_timers();
  EXPECT_EQ(sent(), "407: 00 00 00 00 00 00 00");
  now_ = scanner_->next_deadline();
  run_timers();
  ASSERT_EQ(scanner_->state(), PortState::kRunning);

  EXPECT_EQ(sent(), "466: 40 4B 03 01 01 00");
  answer("463: 40 CB 00");
  EXPECT_EQ(sent(), "464: 00 0E 03 01 05");
  answer("463: 00 8E 03 00");                // [03 choice: explicit + poll][00 master]
  EXPECT_EQ(sent(), "465:");                 // idle
  EXPECT_EQ(sent(), "466: 40 4C 03 01 02");  // then [4C Release][02 poll]
  answer("3CC: 00 1F 00 00 00 00");          // the device's answer to the idle poll
  answer("463: 40 CC");
  EXPECT_EQ(sent(), "464: 00 0E 01 01 01");  // on to the identity
  EXPECT_EQ(node().counters().errors, 0u);
  EXPECT_EQ(node().counters().idle_polls, 1u);
  EXPECT_EQ(states_.last, NodeState::kIdentifying) << states_.last_reason;
}

}  // namespace
}  // namespace dnbridge::devicenet
