#pragma once
// What the tests of the port loop's parts share: pumps on a port with no bus
// (a RackPort whose frames go nowhere), and a publisher that counts what it
// is given. The master's timers and the nodes' events are driven by hand on
// a fake clock.
#include <map>
#include <string>
#include <vector>

#include "adapters/port/port_publisher.hpp"
#include "bridge/can/frame_sink.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::port::test {

inline devicenet::MacId mac(unsigned m) { return *devicenet::MacId::from(m); }

inline rack::PumpConfig pump(unsigned m) {
  rack::PumpConfig p;
  p.node.mac = mac(m);
  p.node.name = "pump " + std::to_string(m);
  p.io = profiles::cdn127::preset(profiles::cdn127::ConfigurationPreset::kCdn127);
  return p;
}

inline rack::PortNodes pumps(std::vector<unsigned> macs) {
  std::vector<rack::PumpConfig> list;
  for (unsigned m : macs) list.push_back(pump(m));
  return rack::PortNodes(std::move(list));
}

class NullSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

// Samples by MAC, in the order given.
class CountingPublisher final : public PortPublisher {
 public:
  void node_state(const std::string&, const rack::NodeView& node, TimePoint t) override {
    states.push_back(node.mac.value());
    state_times[node.mac.value()] = t;
  }
  void node_status(const std::string&, const rack::NodeView& node, const NodeStatusView&,
                   TimePoint) override {
    statuses.push_back(node.mac.value());
  }
  void port_status(const PortStatusView&, TimePoint) override { ++port_statuses; }
  void explicit_reply(const std::string&, const rack::ExplicitAnswer&) override {}
  void bus_scan_reply(const std::string&, const BusScanAnswer& a) override { scans.push_back(a); }
  void port_stopped(const std::string&) override {}
  void node_removed(const std::string&, devicenet::MacId m) override {
    removed.push_back(m.value());
  }
  void clear() {
    states.clear();
    statuses.clear();
  }

  std::vector<unsigned> states;
  std::vector<unsigned> statuses;
  std::map<unsigned, TimePoint> state_times;
  int port_statuses = 0;
  std::vector<BusScanAnswer> scans;
  std::vector<unsigned> removed;
};

}  // namespace dnbridge::port::test
