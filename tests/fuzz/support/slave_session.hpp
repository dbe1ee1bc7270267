#pragma once
// What the simulated slaves' targets (cdn127_slave, eds_slave) share: a
// session replayed on a slave (support/session_records.hpp), its timers run,
// and the properties every frame a Group 2 only slave sends must have.
#include <cstdint>

#include "adapters/sim/generic/group2_slave.hpp"
#include "bridge/can/can_frame.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"
#include "tests/fuzz/support/session_records.hpp"

namespace dnbridge::fuzz {

// Runs the slave's timers due at `now`; after them the next deadline is
// later. A few chained rounds at one instant, more is a spin.
inline void run_timers(sim::Group2Slave& slave, TimePoint now) {
  for (int i = 0; slave.next_deadline() <= now; ++i) {
    FUZZ_CHECK(i < 8);
    slave.on_timer(now);
  }
}

// Replays the input on a slave powered on at kSessionStart: frames received,
// kStop a power cycle, time passing; `other(record, now)` for the target's
// own ops; `check()` after every record.
template <class Other, class Check>
void run_session(sim::Group2Slave& slave, Bytes input, Other other, Check check) {
  TimePoint now = kSessionStart;
  slave.power_on(now);
  ByteReader in(input);
  while (auto record = next_record(in)) {
    now += record->step;
    run_timers(slave, now);
    switch (record->op) {
      case Op::kFrame:
        slave.on_frame(record->frame, now);
        break;
      case Op::kStop:
        slave.power_cycle(now);
        break;
      default:
        other(*record, now);
        break;
    }
    run_timers(slave, now);
    check();
  }
}

// What holds of every frame a slave sends: a CAN 2.0A frame, in time order,
// never while off. In Communication Fault a device answers only the Offline
// Connection Set, which exists to reach it there (Group 4: the communication
// faulted and offline ownership responses, which carry no MAC).
class SentFrameCheck {
 public:
  // False for an Offline Connection Set response (nothing more to check);
  // true when the target checks the frame as its own.
  bool check(const sim::Group2Slave& s, const can::CanFrame& frame, TimePoint now) {
    using NetworkState = sim::Group2Slave::NetworkState;
    FUZZ_CHECK(frame.id <= can::kMaxStandardId);
    FUZZ_CHECK(frame.len <= can::kMaxDataLength);
    FUZZ_CHECK(now >= last_);
    last_ = now;
    FUZZ_CHECK(s.network_state() != NetworkState::kOff);
    if (s.network_state() != NetworkState::kCommunicationFault) return true;
    FUZZ_CHECK(frame.id == devicenet::group4_id(devicenet::Group4Message::kCommFaultedResponse) ||
               frame.id ==
                   devicenet::group4_id(devicenet::Group4Message::kOfflineOwnershipResponse));
    return false;
  }

 private:
  TimePoint last_{};
};

// A frame that is none of the slave's I/O messages: an explicit response or
// the duplicate MAC check's, always with its own MAC, and the check's alone
// while it checks.
inline void check_group2_frame(const sim::Group2Slave& s, devicenet::MacId mac,
                               const can::CanFrame& frame) {
  using devicenet::Group2Message;
  FUZZ_CHECK(frame.id == devicenet::group2_id(mac, Group2Message::kSlaveExplicitResponse) ||
             frame.id == devicenet::group2_id(mac, Group2Message::kDuplicateMacCheck));
  if (s.network_state() == sim::Group2Slave::NetworkState::kDuplicateMacCheck) {
    FUZZ_CHECK(frame.id == devicenet::group2_id(mac, Group2Message::kDuplicateMacCheck));
  }
}

}  // namespace dnbridge::fuzz
