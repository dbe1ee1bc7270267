#pragma once
// What the master tells the layer above. Called from inside the scanner's
// event handling (on the port's own thread): implementations copy what they
// need and return; they must not call back into the scanner.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/explicit_client.hpp"
#include "bridge/devicenet/master/node_state.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

enum class PortState : std::uint8_t {
  kStopped,       // not started, or stopped after an orderly shutdown
  kCheckingMac,   // duplicate MAC ID check of the master's own MAC
  kRunning,       // scanning
  kStopping,      // orderly shutdown: nodes going idle and being released
  kDuplicateMac,  // another node has the master's MAC: nothing is sent
};

std::string_view to_string(PortState state) noexcept;

// The Identity object as read from a node.
struct NodeIdentity {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_type = 0;
  std::uint16_t product_code = 0;
  std::uint8_t major_revision = 0;
  std::uint8_t minor_revision = 0;
  std::uint32_t serial_number = 0;
  std::string product_name;
  // Identity.Status and Identity.State as read at start-up; empty where the
  // device does not support them ("state unknown").
  std::optional<std::uint16_t> status;
  std::optional<std::uint8_t> state;
};

// What a bus scan (Scanner::scan_bus) found at one MAC the scan list does
// not have.
enum class ScanOutcome : std::uint8_t {
  kIdentified,            // allocated, vendor, product type and code read (what else it
                          // refused: detail), released
  kNoAnswer,              // nothing answered the Allocate
  kRefused,               // the Allocate or those three Gets were refused (detail)
  kOwnedByOtherMaster,    // refused: another master holds it (0x0C/0x01)
  kAnsweringOtherMaster,  // heard answering another master: not asked
  kNotAsked,              // the scan ended first (detail: why)
};
std::string_view to_string(ScanOutcome outcome) noexcept;

struct ScanFinding {
  MacId mac;
  ScanOutcome outcome = ScanOutcome::kNotAsked;
  NodeIdentity identity;  // kIdentified; Status and State are not read
  std::string detail;     // for people; empty when there is nothing to add
};

// A whole scan: every MAC but the master's and the scan list's, in order.
struct BusScan {
  std::vector<ScanFinding> findings;
  TimePoint started{};
  TimePoint finished{};
  std::string error;  // why it ended early (the port stopped); empty when complete
};

class ScannerObserver {
 public:
  virtual ~ScannerObserver() = default;
  virtual void on_port_state(PortState /*state*/, const std::string& /*reason*/, TimePoint /*at*/) {
  }
  // Every life-cycle transition, with its reason.
  virtual void on_node_state(MacId /*mac*/, NodeState /*from*/, NodeState /*to*/,
                             const std::string& /*reason*/, TimePoint /*at*/) {}
  virtual void on_node_identity(MacId /*mac*/, const NodeIdentity& /*identity*/, TimePoint /*at*/) {
  }
  // A poll response of the expected size, or empty: an idle poll answered
  // with no data (Node::applied_idle()); `rx_time` is the CAN receive time.
  virtual void on_poll_response(MacId /*mac*/, Bytes /*data*/, TimePoint /*rx_time*/) {}
  // Identity object State (attribute 8) read by the keep-alive, when it changes.
  virtual void on_device_state(MacId /*mac*/, std::uint8_t /*state*/, TimePoint /*at*/) {}
  // The end of an explicit request submitted with Scanner::request_explicit.
  virtual void on_explicit_result(std::uint32_t /*request_id*/, MacId /*mac*/,
                                  const ExplicitResult& /*result*/, TimePoint /*at*/) {}
  // A node the scan list does not have was heard for the first time
  // (Scanner::unconfigured_heard).
  virtual void on_unconfigured_node(MacId /*mac*/, TimePoint /*at*/) {}
  // The end of a bus scan started with Scanner::scan_bus.
  virtual void on_bus_scan(const BusScan& /*scan*/, TimePoint /*at*/) {}
};

}  // namespace dnbridge::devicenet

namespace dnbridge::devicenet {

// Hands every event to each of several observers, in order.
class ObserverFanout final : public ScannerObserver {
 public:
  void add(ScannerObserver& o) { observers_.push_back(&o); }
  // Hears the events before the observers from `position` on.
  void insert(std::size_t position, ScannerObserver& o) {
    observers_.insert(observers_.begin() + static_cast<std::ptrdiff_t>(position), &o);
  }

  void on_port_state(PortState s, const std::string& r, TimePoint at) override {
    for (auto* o : observers_) o->on_port_state(s, r, at);
  }
  void on_node_state(MacId m, NodeState f, NodeState t, const std::string& r,
                     TimePoint at) override {
    for (auto* o : observers_) o->on_node_state(m, f, t, r, at);
  }
  void on_node_identity(MacId m, const NodeIdentity& i, TimePoint at) override {
    for (auto* o : observers_) o->on_node_identity(m, i, at);
  }
  void on_poll_response(MacId m, Bytes d, TimePoint at) override {
    for (auto* o : observers_) o->on_poll_response(m, d, at);
  }
  void on_device_state(MacId m, std::uint8_t s, TimePoint at) override {
    for (auto* o : observers_) o->on_device_state(m, s, at);
  }
  void on_explicit_result(std::uint32_t id, MacId m, const ExplicitResult& r,
                          TimePoint at) override {
    for (auto* o : observers_) o->on_explicit_result(id, m, r, at);
  }
  void on_unconfigured_node(MacId m, TimePoint at) override {
    for (auto* o : observers_) o->on_unconfigured_node(m, at);
  }
  void on_bus_scan(const BusScan& s, TimePoint at) override {
    for (auto* o : observers_) o->on_bus_scan(s, at);
  }

 private:
  std::vector<ScannerObserver*> observers_;
};

}  // namespace dnbridge::devicenet
