#pragma once
// Shared set-up for the master-against-simulator tests: a rack port with a
// scan list of CDN127 pumps, and a recorder of the master's events.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "adapters/sim/world/sim_rack.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::test {

using devicenet::MacId;
using devicenet::NodeState;

inline MacId mac(unsigned v) { return MacId::from(v).value(); }

// Every event the master reports, for assertions on sequences and reasons.
class EventRecorder final : public devicenet::ScannerObserver {
 public:
  struct Transition {
    MacId mac;
    NodeState from;
    NodeState to;
    std::string reason;
    TimePoint at;
  };
  struct ExplicitDone {
    std::uint32_t id;
    MacId mac;
    devicenet::ExplicitResult result;
  };

  void on_port_state(devicenet::PortState s, const std::string& r, TimePoint) override {
    port_states.push_back(s);
    port_reason = r;
  }
  void on_node_state(MacId m, NodeState f, NodeState t, const std::string& r,
                     TimePoint at) override {
    transitions.push_back({m, f, t, r, at});
  }
  void on_explicit_result(std::uint32_t id, MacId m, const devicenet::ExplicitResult& r,
                          TimePoint) override {
    explicit_results.push_back({id, m, r});
  }
  void on_bus_scan(const devicenet::BusScan& scan, TimePoint) override {
    bus_scans.push_back(scan);
  }

  std::vector<Transition> of(MacId m) const {
    std::vector<Transition> out;
    for (const auto& t : transitions) {
      if (t.mac == m) out.push_back(t);
    }
    return out;
  }
  const ExplicitDone* result(std::uint32_t id) const {
    for (const auto& r : explicit_results) {
      if (r.id == id) return &r;
    }
    return nullptr;
  }

  std::vector<devicenet::PortState> port_states;
  std::string port_reason;
  std::vector<Transition> transitions;
  std::vector<ExplicitDone> explicit_results;
  std::vector<devicenet::BusScan> bus_scans;
};

inline rack::PumpConfig pump(unsigned mac_value,
                             profiles::cdn127::IoConfiguration io = profiles::cdn127::preset(
                                 profiles::cdn127::ConfigurationPreset::kCdn127)) {
  rack::PumpConfig p;
  p.node.mac = mac(mac_value);
  p.node.name = "pump " + std::to_string(mac_value);
  p.node.poll_period = milliseconds(100);
  p.node.expected_packet_rate = milliseconds(500);
  p.io = io;
  return p;
}

inline sim::SimRackConfig rack_config(std::vector<unsigned> macs, unsigned master = 0) {
  sim::SimRackConfig c;
  c.bus.bitrate = can::kBitrate500k;
  c.port.master_mac = mac(master);
  c.port.vendor_id = 59;
  c.port.serial_number = 0xDB000001;
  for (unsigned m : macs) c.pumps.push_back(pump(m));
  return c;
}

}  // namespace dnbridge::test

namespace dnbridge::test {

// Counts what reaches the log, by level.
class CountingLogSink final : public LogSink {
 public:
  bool enabled(LogLevel level) const noexcept override { return level >= LogLevel::kInfo; }
  void write(LogLevel level, std::string_view, std::string_view message) override {
    if (level >= LogLevel::kWarn) {
      ++warnings;
      last_warning = std::string(message);
    } else {
      last_info = std::string(message);
    }
  }
  std::size_t warnings = 0;
  std::string last_warning;
  std::string last_info;
};

}  // namespace dnbridge::test
