// The simulated CDN127 driven by received frames and the passing of time from
// the input (support/session_records.hpp; op kStop power-cycles it). Frames it
// sends are checked and dropped. Properties: no crash or sanitizer report;
// after on_timer(now) the next deadline is after now; every frame sent is a
// valid CAN 2.0A frame from this device's MAC; a device in Communication
// Fault answers only the Offline Connection Set (Group 4), which exists to
// reach it there; its state stays within what the device can hold.
#include "adapters/sim/cdn127/cdn127_slave.hpp"

#include <cstddef>
#include <cstdint>

#include "bridge/devicenet/wire/identifier.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"
#include "tests/fuzz/support/session_records.hpp"

namespace {

using namespace dnbridge;
using devicenet::Group1Message;
using devicenet::Group2Message;
using devicenet::Group4Message;
using devicenet::MacId;
using sim::Cdn127Slave;

class CheckingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint now) override {
    FUZZ_CHECK(slave_ != nullptr);
    FUZZ_CHECK(frame.id <= can::kMaxStandardId);
    FUZZ_CHECK(frame.len <= can::kMaxDataLength);
    FUZZ_CHECK(now >= last_);
    last_ = now;
    FUZZ_CHECK(slave_->network_state() != Cdn127Slave::NetworkState::kOff);
    // In Communication Fault a device answers only the Offline Connection
    // Set, which exists to reach it there (Group 4: the communication
    // faulted and offline ownership responses, which carry no MAC).
    const bool offline_response =
        frame.id == devicenet::group4_id(Group4Message::kCommFaultedResponse) ||
        frame.id == devicenet::group4_id(Group4Message::kOfflineOwnershipResponse);
    if (slave_->network_state() == Cdn127Slave::NetworkState::kCommunicationFault) {
      FUZZ_CHECK(offline_response);
      return;
    }
    // Otherwise a Group 2 only slave answers on Group 1 message 15 and Group
    // 2 messages 3 and 7, always with its own MAC.
    const MacId mac = slave_->mac();
    FUZZ_CHECK(frame.id == devicenet::group1_id(Group1Message::kSlavePollResponse, mac) ||
               frame.id == devicenet::group2_id(mac, Group2Message::kSlaveExplicitResponse) ||
               frame.id == devicenet::group2_id(mac, Group2Message::kDuplicateMacCheck));
    if (slave_->network_state() == Cdn127Slave::NetworkState::kDuplicateMacCheck) {
      FUZZ_CHECK(frame.id == devicenet::group2_id(mac, Group2Message::kDuplicateMacCheck));
    }
  }
  const Cdn127Slave* slave_ = nullptr;

 private:
  TimePoint last_{};
};

void run_timers(Cdn127Slave& slave, TimePoint now) {
  for (int i = 0; slave.next_deadline() <= now; ++i) {
    FUZZ_CHECK(i < 8);  // a few chained rounds at one instant, more is a spin
    slave.on_timer(now);
  }
}

void check_consistent(const Cdn127Slave& slave) {
  FUZZ_CHECK(slave.mac().value() <= MacId::kMax);
  const std::uint8_t owner = slave.owner();
  FUZZ_CHECK(owner == MacId::kNone || owner <= MacId::kMax);
  // Connections exist only while a master owns the connection set.
  if (owner == MacId::kNone) {
    FUZZ_CHECK(slave.explicit_state() == sim::ConnectionState::kNonExistent);
    FUZZ_CHECK(slave.poll_state() == sim::ConnectionState::kNonExistent);
  }
  FUZZ_CHECK(profiles::cdn127::validate(slave.device().configuration()).ok());
  FUZZ_CHECK(profiles::cdn127::validate(slave.outputs()).ok());
  const auto& c = slave.counters();
  FUZZ_CHECK(c.restarts >= 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  CheckingSink sink;
  Cdn127Slave slave(sink, fuzz::fuzz_slave_options());
  sink.slave_ = &slave;

  TimePoint now = fuzz::kSessionStart;
  slave.power_on(now);
  ByteReader in(Bytes(data, size));
  while (auto record = fuzz::next_record(in)) {
    now += record->step;
    run_timers(slave, now);
    switch (record->op) {
      case fuzz::Op::kFrame:
        slave.on_frame(record->frame, now);
        break;
      case fuzz::Op::kStop:
        slave.power_cycle(now);
        break;
      default:  // the master's requests mean nothing here: time passes
        break;
    }
    run_timers(slave, now);
    check_consistent(slave);
  }
  return 0;
}
