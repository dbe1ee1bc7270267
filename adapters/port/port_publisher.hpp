#pragma once
// What a port's loop hands to the DDS face: plain views, called on the
// port's own thread. Implementations copy what they need and return quickly.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "adapters/port/can_backend.hpp"
#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/explicit_gateway.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::port {

struct PortStatusView {
  std::string port;
  std::string interface_name;
  std::uint32_t bitrate = 0;
  devicenet::MacId master_mac;
  devicenet::PortState state = devicenet::PortState::kStopped;
  std::string reason;
  BusCounters bus;
  double frames_per_second = 0;
  double bus_load_percent = 0;
  double scan_cycle_ms = 0;  // mean interval between two polls of an online node
  std::uint16_t nodes_online = 0;
  std::uint16_t nodes_configured = 0;
  std::uint32_t explicit_outstanding = 0;  // queued for the loop or executing
  std::uint32_t explicit_retained = 0;
  std::uint64_t explicit_refused_for_limits = 0;
  double loop_longest_pass_ms = 0;  // since the previous PortStatus
  // MACs heard on the bus that the configuration does not have, ascending.
  std::vector<std::uint8_t> unconfigured_macs;
};

// A node as the master sees it, copied on the port's thread: what NodeStatus
// says of it. No live devicenet::Node crosses into the DDS face.
struct NodeStatusView {
  devicenet::NodeState state = devicenet::NodeState::kAbsent;
  std::string reason;
  devicenet::NodeIdentity identity;
  std::optional<std::uint8_t> device_state;
  Duration poll_period{};
  Duration poll_epr{};
  std::size_t produced_size = 0;
  std::size_t consumed_size = 0;
  devicenet::NodeError last_error;
  devicenet::NodeCounters counters;
  devicenet::ExplicitCounters explicit_counters;

  static NodeStatusView of(const devicenet::Node& node);
};

// A bus scan request as received (BusScanRequest).
struct ScanCall {
  std::string requester;
  std::uint32_t txid = 0;
};

// The answer to a bus scan request (BusScanRequest): a port's scan, run for
// it or joined, or the last one again.
struct BusScanAnswer {
  std::string requester;
  std::uint32_t txid = 0;
  rack::TransactionStatus status = rack::TransactionStatus::kSuccess;
  std::string message;
  Duration duration{};  // the scan's
  Duration age{};       // since the scan ended, when it answered an earlier request
  std::vector<devicenet::ScanFinding> findings;
};

// An answer that refuses `call` without a scan (as rack::refuse for an
// explicit request).
inline BusScanAnswer refuse(const ScanCall& call, rack::TransactionStatus status,
                            std::string message) {
  BusScanAnswer a;
  a.requester = call.requester;
  a.txid = call.txid;
  a.status = status;
  a.message = std::move(message);
  return a;
}

class PortPublisher {
 public:
  virtual ~PortPublisher() = default;
  // `source_time` is the monotonic time of the event the sample comes from
  // (a frame's receive time, or a timer's); the publisher maps it to the
  // wall clock DDS timestamps use. A node's state, on its profile's topic
  // (`node.profile`: PumpState for "cdn127", DeviceState for "eds"), and
  // its NodeStatus; the view is that profile's (rack::PumpView,
  // rack::DeviceView).
  virtual void node_state(const std::string& port, const rack::NodeView& node,
                          TimePoint source_time) = 0;
  virtual void node_status(const std::string& port, const rack::NodeView& node,
                           const NodeStatusView& status, TimePoint source_time) = 0;
  virtual void port_status(const PortStatusView& status, TimePoint source_time) = 0;
  // `port`: the port whose gateway answers; empty for a request no port took.
  virtual void explicit_reply(const std::string& port, const rack::ExplicitAnswer& answer) = 0;
  // `port`: the port scanned, or the port asked for when it does not exist.
  virtual void bus_scan_reply(const std::string& port, const BusScanAnswer& answer) = 0;
  // The port has stopped: its instances are unregistered (never disposed).
  virtual void port_stopped(const std::string& port) = 0;
  // The node left the port's configuration (a reload): its instances are
  // disposed, after its last samples.
  virtual void node_removed(const std::string& port, devicenet::MacId mac) = 0;
};

}  // namespace dnbridge::port
