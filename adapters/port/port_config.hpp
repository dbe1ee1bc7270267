#pragma once
// What one port runs with (PortLoopConfig), and what a configuration read
// again changed on it (PortChange).
#include <map>
#include <string>
#include <vector>

#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/explicit_policy.hpp"
#include "bridge/rack/port_nodes.hpp"
#include "bridge/rack/publish_gate.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::port {

struct PortLoopConfig {
  std::string port;                  // the port's name
  devicenet::ScannerConfig scanner;  // master MAC and timings; nodes from `nodes`
  rack::PortNodes nodes;             // the scan list, by profile
  // Per node; PublishPolicy{} for a node not named.
  std::map<devicenet::MacId, rack::PublishPolicy> publish;
  rack::ExplicitPolicy explicit_policy;    // the rack's [explicit_policy]
  Duration status_period = seconds(1);     // NodeStatus/PortStatus at least this often
  Duration shutdown_timeout = seconds(3);  // for idling and releasing every node
};

// What a configuration read again changed on a port (PortLoop::reconfigure).
struct PortChange {
  rack::ScanListChange scan_list;
  std::vector<devicenet::MacId> publish_changed;  // nodes kept whose publish policy changed
  bool explicit_policy_changed = false;
  // Not empty: the port refused the configuration, and nothing changed.
  std::string refused;

  bool any() const {
    return scan_list.any() || !publish_changed.empty() || explicit_policy_changed;
  }
};

}  // namespace dnbridge::port
