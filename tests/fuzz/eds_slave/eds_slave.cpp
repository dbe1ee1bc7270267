// The simulated device driven by an EDS file (EdsSlave at MAC 1: the example
// I/O block of deploy/eds, then the example valve manifold, each given the
// whole input), driven by received frames in any order and the passing of
// time from the input (support/session_records.hpp: op kStop power-cycles
// it; op kSetOutputs is the device's own inputs changing, data [digital
// inputs][status] for the I/O block, [status] for the manifold, then
// inputs_changed()). Frames it sends are
// checked and dropped. Properties: no crash or sanitizer report; after
// on_timer(now) the next deadline is after now; every frame sent is a valid
// CAN 2.0A frame with a DeviceNet identifier of this device's MAC (Group 1
// messages 13 and 15, Group 2 messages 3 and 7), and, in Communication
// Fault, only the Offline Connection Set's; a poll response, a
// change-of-state message and a bit-strobe response carry the data of the
// assembly their connection produces, whole (it fits one frame); a
// change-of-state message goes out only while instance 4 produces, and it
// produces exactly while it is Established; a bit-strobe response only while
// instance 3 is Established; connections exist only while a master owns the
// set.
#include "adapters/sim/generic/eds_slave.hpp"

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "bridge/devicenet/wire/identifier.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"
#include "tests/fuzz/support/slave_session.hpp"

namespace {

using namespace dnbridge;
using devicenet::Group1Message;
using devicenet::MacId;
using sim::ConnectionState;
using sim::EdsSlave;

constexpr std::uint8_t kMac = 1;
// The example I/O block's parameters the inputs are made of: digital inputs
// (USINT) and module status (BYTE).
constexpr unsigned kDigitalInputs = 3;
constexpr unsigned kModuleStatus = 5;

profiles::eds::EdsFile read_example(const char* name) {
  std::ifstream in(std::string(DNBRIDGE_EDS_DIR) + "/" + name);
  std::stringstream text;
  text << in.rdbuf();
  auto parsed = profiles::eds::parse(text.str());
  FUZZ_CHECK(parsed.file.has_value());
  return std::move(*parsed.file);
}

// deploy/eds's examples, read once.
const profiles::eds::EdsFile& io_block() {
  static const profiles::eds::EdsFile file = read_example("dnbridge-example-io-block.eds");
  return file;
}
const profiles::eds::EdsFile& valve_manifold() {
  static const profiles::eds::EdsFile file = read_example("dnbridge-example-valve-manifold.eds");
  return file;
}

class CheckingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint now) override {
    FUZZ_CHECK(slave_ != nullptr);
    const EdsSlave& s = *slave_;
    if (!common_.check(s, frame, now)) return;
    const MacId mac = s.mac();
    const Bytes payload = frame.payload();
    // An I/O message: only while its connection is Established (and, for
    // change of state, producing), its assembly's data whole.
    struct IoMessage {
      Group1Message message;
      ConnectionState state;
      const sim::Connection& connection;
    };
    const sim::ConnectionSet& c = s.connections();
    for (const IoMessage& m :
         {IoMessage{Group1Message::kSlaveCosCyclic, s.cos_state(), c.cos_connection()},
          IoMessage{Group1Message::kSlaveBitStrobeResponse, s.strobe_state(),
                    c.strobe_connection()},
          IoMessage{Group1Message::kSlavePollResponse, s.poll_state(), c.poll_connection()}}) {
      if (frame.id != devicenet::group1_id(m.message, mac)) continue;
      FUZZ_CHECK(s.network_state() == EdsSlave::NetworkState::kOnline);
      FUZZ_CHECK(m.state == ConnectionState::kEstablished);
      if (m.message == Group1Message::kSlaveCosCyclic) FUZZ_CHECK(s.cos_producing());
      FUZZ_CHECK(payload.size() ==
                 s.objects().assembly_data(m.connection.produced_assembly).size());
      return;
    }
    fuzz::check_group2_frame(s, mac, frame);
  }
  const EdsSlave* slave_ = nullptr;

 private:
  fuzz::SentFrameCheck common_;
};

void check_consistent(const EdsSlave& slave) {
  FUZZ_CHECK(slave.mac().value() == kMac);  // the MAC is the switches'
  const std::uint8_t owner = slave.owner();
  FUZZ_CHECK(owner == MacId::kNone || owner <= MacId::kMax);
  if (owner == MacId::kNone) {
    FUZZ_CHECK(slave.explicit_state() == ConnectionState::kNonExistent);
    FUZZ_CHECK(slave.poll_state() == ConnectionState::kNonExistent);
    FUZZ_CHECK(slave.cos_state() == ConnectionState::kNonExistent);
    FUZZ_CHECK(slave.strobe_state() == ConnectionState::kNonExistent);
  }
  // Instance 4 produces exactly while it is Established.
  FUZZ_CHECK(slave.cos_producing() == (slave.cos_state() == ConnectionState::kEstablished));
  // What the I/O connections carry fits one frame (no I/O fragmentation).
  for (const sim::Connection* c :
       {&slave.connections().poll_connection(), &slave.connections().cos_connection(),
        &slave.connections().strobe_connection()}) {
    FUZZ_CHECK(slave.objects().assembly_data(c->produced_assembly).size() <= sim::kMaxPollData);
    FUZZ_CHECK(slave.objects().assembly_data(c->consumed_assembly).size() <= sim::kMaxPollData);
  }
  // A poll command lands in an output assembly, never the inputs'.
  const std::uint16_t consumed = slave.connections().poll_connection().consumed_assembly;
  FUZZ_CHECK(consumed == 0 || consumed == slave.poll_output_assembly());
  FUZZ_CHECK(slave.connections().cos_connection().consumed_assembly == 0);
  FUZZ_CHECK(slave.connections().strobe_connection().consumed_assembly == 0);
}

void run(const profiles::eds::EdsFile& file, Bytes input) {
  CheckingSink sink;
  sim::EdsSlaveOptions options;
  options.mac = kMac;
  options.serial_number = 0xDB000101;
  EdsSlave slave(sink, file, options);
  sink.slave_ = &slave;
  const bool manifold = &file == &valve_manifold();

  fuzz::run_session(
      slave, input,
      [&](const fuzz::Record& record, TimePoint now) {
        if (record.op != fuzz::Op::kSetOutputs) return;  // the master's other requests: time passes
        const Bytes d = record.frame.payload();
        if (manifold) {
          if (!d.empty())
            (void)slave.objects().set_assembly_data(slave.strobe_input_assembly(), d.first(1));
        } else {
          if (!d.empty()) (void)slave.objects().set_param_value(kDigitalInputs, d.first(1));
          if (d.size() > 1) (void)slave.objects().set_param_value(kModuleStatus, d.subspan(1, 1));
        }
        slave.inputs_changed(now);
      },
      [&] { check_consistent(slave); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  run(io_block(), Bytes(data, size));
  run(valve_manifold(), Bytes(data, size));
  return 0;
}
