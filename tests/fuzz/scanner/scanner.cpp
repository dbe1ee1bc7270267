// The master of one port driven by received frames, the passing of time and
// the requests of the layer above, all taken from the input
// (support/session_records.hpp). Frames it sends are checked and dropped.
// The scan list changes too (nodes taken out and put back, as a reload
// does). Properties: no crash or sanitizer report; after on_timer(now) the
// next deadline is after now (an event loop would otherwise spin); every
// frame sent is a valid CAN 2.0A frame; events are consistent with the scan
// list and with each other.
#include "bridge/devicenet/master/scanner.hpp"

#include <algorithm>
#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "bridge/devicenet/wire/identifier.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"
#include "tests/fuzz/support/session_records.hpp"

namespace {

using namespace dnbridge;
using devicenet::MacId;
using devicenet::NodeState;
using devicenet::PortState;

class CheckingSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint now) override {
    FUZZ_CHECK(frame.id <= can::kMaxStandardId);
    FUZZ_CHECK(frame.len <= can::kMaxDataLength);
    FUZZ_CHECK(now >= last_);
    last_ = now;
    // The bit-strobe command: the master's, 8 bytes, every bit 0.
    if (frame.id == devicenet::group2_id(devicenet::MacId::from(0).value(),
                                         devicenet::Group2Message::kMasterBitStrobeCommand)) {
      FUZZ_CHECK(frame.len == 8);
      FUZZ_CHECK(
          std::all_of(frame.data.begin(), frame.data.end(), [](std::uint8_t b) { return b == 0; }));
    }
  }

 private:
  TimePoint last_{};
};

// Follows the events and checks them against what the scanner says.
class CheckingObserver final : public devicenet::ScannerObserver {
 public:
  explicit CheckingObserver(const devicenet::ScannerConfig& config) : config_(config) {
    states_.fill(NodeState::kAbsent);
  }

  void on_port_state(PortState, const std::string&, TimePoint at) override { check_time(at); }
  void on_node_state(MacId mac, NodeState from, NodeState to, const std::string&,
                     TimePoint at) override {
    check_time(at);
    FUZZ_CHECK(find(mac) != nullptr);
    // from == to is allowed: the same state with a new reason is news too.
    // Each transition starts where the previous one for that node ended; a
    // node put back at a MAC starts anew, absent.
    FUZZ_CHECK(from == states_[mac.value()] ||
               (readded_.test(mac.value()) && from == NodeState::kAbsent));
    states_[mac.value()] = to;
  }
  void on_node_identity(MacId mac, const devicenet::NodeIdentity&, TimePoint at) override {
    check_time(at);
    FUZZ_CHECK(find(mac) != nullptr);
  }
  void on_poll_response(MacId mac, Bytes data, TimePoint at) override {
    check_time(at);
    const auto* node = find(mac);
    FUZZ_CHECK(node != nullptr);
    // Only responses of the configured size reach the layer above, and empty
    // ones to an idle poll (a valid answer that carries no inputs).
    if (data.empty() && node->profile.produced_size != 0) {
      FUZZ_CHECK(scanner_ != nullptr && scanner_->node(mac)->applied_idle());
    } else {
      FUZZ_CHECK(data.size() == node->profile.produced_size);
    }
    FUZZ_CHECK(states_[mac.value()] == NodeState::kOnline);
  }
  void on_device_state(MacId mac, std::uint8_t, TimePoint at) override {
    check_time(at);
    FUZZ_CHECK(find(mac) != nullptr);
  }
  void on_explicit_result(std::uint32_t id, MacId mac, const devicenet::ExplicitResult& r,
                          TimePoint at) override {
    check_time(at);
    FUZZ_CHECK(find(mac) != nullptr);
    FUZZ_CHECK((id & devicenet::Node::kInternalTag) == 0);
    FUZZ_CHECK(r.data.size() <= devicenet::kMaxExplicitMessage);
    ++results_;
  }

  // A scan's findings: every MAC but the master's and the scan list's, once,
  // ascending; an identity only where the node was identified.
  void on_bus_scan(const devicenet::BusScan& scan, TimePoint at) override {
    check_time(at);
    FUZZ_CHECK(scan.started <= scan.finished && scan.finished == at);
    // A change of the scan list ends a scan first: the list is the scan's.
    FUZZ_CHECK(scan.findings.size() >= MacId::kMax - config_.nodes.size());
    FUZZ_CHECK(scan.findings.size() <= MacId::kMax - scanner_->nodes().size());
    unsigned previous = 0;
    bool first = true;
    for (const auto& f : scan.findings) {
      FUZZ_CHECK(f.mac != config_.master_mac && scanner_->node(f.mac) == nullptr);
      FUZZ_CHECK(first || f.mac.value() > previous);
      first = false;
      previous = f.mac.value();
      if (f.outcome != devicenet::ScanOutcome::kIdentified) {
        FUZZ_CHECK(f.identity.vendor_id == 0 && f.identity.product_name.empty());
      }
      if (f.outcome == devicenet::ScanOutcome::kNotAsked) FUZZ_CHECK(!scan.error.empty());
    }
  }

  NodeState state(MacId mac) const { return states_[mac.value()]; }
  // A node was put back at `mac`, in `state` when no node taken out from
  // there is still being released (a node added to a port that does not
  // scan reports nothing until it starts).
  void readded(MacId mac, std::optional<NodeState> state) {
    readded_.set(mac.value());
    if (state) states_[mac.value()] = *state;
  }
  // The scanner it observes, for what the events do not carry.
  void watch(const devicenet::Scanner& scanner) { scanner_ = &scanner; }
  std::uint64_t results() const { return results_; }

 private:
  const devicenet::NodeConfig* find(MacId mac) const {
    for (const auto& n : config_.nodes) {
      if (n.mac == mac) return &n;
    }
    return nullptr;
  }
  void check_time(TimePoint at) {
    FUZZ_CHECK(at >= last_);
    last_ = at;
  }

  const devicenet::ScannerConfig& config_;
  const devicenet::Scanner* scanner_ = nullptr;
  std::array<NodeState, MacId::kMax + 1> states_{};
  std::bitset<MacId::kMax + 1> readded_;
  TimePoint last_{};
  std::uint64_t results_ = 0;
};

// Runs the timers due at `now`, as the port's event loop does.
void run_timers(devicenet::Scanner& scanner, TimePoint now) {
  for (int i = 0; scanner.next_deadline() <= now; ++i) {
    // Each call must move the deadline past now; a few rounds are tolerated
    // for work that legitimately chains at one instant, more is a spin.
    FUZZ_CHECK(i < 8);
    scanner.on_timer(now);
  }
}

void check_consistent(const devicenet::Scanner& scanner, const CheckingObserver& observer,
                      const devicenet::ScannerConfig& config,
                      const std::bitset<MacId::kMax + 1>& listed) {
  FUZZ_CHECK(scanner.nodes().size() == listed.count());
  for (const auto& n : config.nodes) {
    const devicenet::Node* node = scanner.node(n.mac);
    if (!listed.test(n.mac.value())) {
      FUZZ_CHECK(node == nullptr);
      continue;
    }
    FUZZ_CHECK(node != nullptr);
    FUZZ_CHECK(node->mac() == n.mac);
    // While a node taken out is released, the events of its MAC are its own.
    if (!scanner.leaving(n.mac)) FUZZ_CHECK(node->state() == observer.state(n.mac));
    FUZZ_CHECK(node->applied_outputs().size() <= devicenet::Node::kMaxIoSize);
    const auto& c = node->counters();
    FUZZ_CHECK(c.idle_polls <= c.polls);
  }
  const auto& pc = scanner.counters();
  FUZZ_CHECK(pc.invalid_identifiers + pc.foreign_frames + pc.unknown_nodes <= pc.frames_received);
  if (scanner.state() == PortState::kDuplicateMac || scanner.state() == PortState::kCheckingMac) {
    for (const auto& node : scanner.nodes()) {
      FUZZ_CHECK(node->state() != NodeState::kOnline);
    }
  }
}

devicenet::RequestMessage request_from(Bytes data) {
  ByteReader r(data);
  devicenet::RequestMessage m;
  m.service = static_cast<std::uint8_t>(r.u8() & 0x7F);
  m.class_id = r.u8();
  m.instance_id = r.u8();
  if (cip::has_attribute(static_cast<cip::Service>(m.service))) m.attribute = r.u8();
  if (r.ok()) m.data = r.rest();
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const devicenet::ScannerConfig config = fuzz::fuzz_scanner_config();
  CheckingSink sink;
  CheckingObserver observer(config);
  devicenet::Scanner scanner(config, sink, observer, Logger());
  observer.watch(scanner);

  std::bitset<MacId::kMax + 1> listed;
  for (const auto& n : config.nodes) listed.set(n.mac.value());
  TimePoint now = fuzz::kSessionStart;
  scanner.start(now);
  ByteReader in(Bytes(data, size));
  while (auto record = fuzz::next_record(in)) {
    now += record->step;
    run_timers(scanner, now);
    const Bytes payload = record->frame.payload();
    const auto& node_mac = [&] {
      const std::size_t i = payload.empty() ? 0 : payload[0] % config.nodes.size();
      return config.nodes[i].mac;
    };
    const Bytes rest = payload.empty() ? payload : payload.subspan(1);
    switch (record->op) {
      case fuzz::Op::kFrame:
        scanner.on_frame(record->frame, now);
        break;
      case fuzz::Op::kTimer:
        break;
      case fuzz::Op::kSetOutputs:
        (void)scanner.set_outputs(node_mac(), rest, now);
        break;
      case fuzz::Op::kSetIdle:
        (void)scanner.set_idle(node_mac(), !rest.empty() && (rest[0] & 1) != 0, now);
        break;
      case fuzz::Op::kRequestExplicit: {
        auto id = scanner.request_explicit(node_mac(), request_from(rest), now);
        if (id) FUZZ_CHECK((*id & devicenet::Node::kInternalTag) == 0);
        break;
      }
      case fuzz::Op::kStop:
        scanner.stop(now);
        break;
      case fuzz::Op::kScanBus: {
        const bool can_start = scanner.state() == PortState::kRunning && !scanner.scanning_bus();
        FUZZ_CHECK(scanner.scan_bus(now).ok() == can_start);
        break;
      }
      case fuzz::Op::kToggleNode: {
        const MacId mac = node_mac();
        const bool stopping = scanner.state() == PortState::kStopping;
        if (listed.test(mac.value())) {
          const Status s = scanner.remove_node(mac, now);
          FUZZ_CHECK(s.ok() == !stopping);
          if (s) listed.reset(mac.value());
        } else {
          devicenet::NodeConfig again =
              *std::find_if(config.nodes.begin(), config.nodes.end(),
                            [&](const devicenet::NodeConfig& n) { return n.mac == mac; });
          if (!rest.empty() && (rest[0] & 1) != 0) {
            again.poll_period *= 2;
            again.expected_packet_rate *= 2;
          }
          observer.readded(mac, std::nullopt);  // before: starting is an event
          const Status s = scanner.add_node(again, now);
          FUZZ_CHECK(s.ok() == !stopping);
          if (s) {
            listed.set(mac.value());
            observer.readded(mac, scanner.leaving(mac) ? std::nullopt
                                                       : std::optional(scanner.node(mac)->state()));
          }
        }
        FUZZ_CHECK(!scanner.scanning_bus());
        break;
      }
    }
    // The work a received frame or request starts may be due at once.
    run_timers(scanner, now);
    check_consistent(scanner, observer, config, listed);
  }
  return 0;
}
