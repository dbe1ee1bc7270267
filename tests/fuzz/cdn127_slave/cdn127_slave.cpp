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
#include "tests/fuzz/support/slave_session.hpp"

namespace {

using namespace dnbridge;
using devicenet::Group1Message;
using devicenet::MacId;
using sim::Cdn127Slave;

class CheckingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint now) override {
    FUZZ_CHECK(slave_ != nullptr);
    if (!common_.check(*slave_, frame, now)) return;
    // A Group 2 only slave's one I/O message: the poll response.
    const MacId mac = slave_->mac();
    if (frame.id == devicenet::group1_id(Group1Message::kSlavePollResponse, mac)) return;
    fuzz::check_group2_frame(*slave_, mac, frame);
  }
  const Cdn127Slave* slave_ = nullptr;

 private:
  fuzz::SentFrameCheck common_;
};

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

  fuzz::run_session(
      slave, Bytes(data, size),
      [](const fuzz::Record&, TimePoint) {},  // the master's requests: time passes
      [&] { check_consistent(slave); });
  return 0;
}
