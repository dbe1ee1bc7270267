#include "bridge/rack/rack_port.hpp"

#include <algorithm>
#include <stdexcept>

namespace dnbridge::rack {
namespace {

using devicenet::MacId;

// The settings the master brings to the device: a difference means
// releasing the node and configuring it again.
bool same_device_settings(const PumpConfig& a, const PumpConfig& b) {
  devicenet::NodeConfig na = a.node;
  devicenet::NodeConfig nb = b.node;
  na.name.clear();
  nb.name.clear();
  return na == nb && a.io == b.io && a.safe_state == b.safe_state && a.identity == b.identity;
}

bool same_handling(const PumpConfig& a, const PumpConfig& b) {
  return a.node.name == b.node.name && a.no_commander == b.no_commander && a.resume == b.resume;
}

const PumpConfig* at(const std::vector<PumpConfig>& pumps, MacId mac) {
  auto it = std::find_if(pumps.begin(), pumps.end(),
                         [&](const PumpConfig& p) { return p.node.mac == mac; });
  return it == pumps.end() ? nullptr : &*it;
}

}  // namespace

ScanListChange compare(const devicenet::ScannerConfig& port_before,
                       const std::vector<PumpConfig>& before,
                       const devicenet::ScannerConfig& port_after,
                       const std::vector<PumpConfig>& after) {
  ScanListChange c;
  c.timings_changed = !devicenet::Scanner::same_timings(port_before, port_after);
  for (unsigned m = 0; m <= MacId::kMax; ++m) {
    const MacId mac = *MacId::from(m);
    const PumpConfig* was = at(before, mac);
    const PumpConfig* is = at(after, mac);
    if (!was && !is) continue;
    if (!was) {
      c.added.push_back(mac);
    } else if (!is) {
      c.removed.push_back(mac);
    } else if (!same_device_settings(*was, *is)) {
      c.reconfigured.push_back(mac);
    } else if (!same_handling(*was, *is)) {
      c.updated.push_back(mac);
    } else {
      c.unchanged.push_back(mac);
    }
  }
  return c;
}

RackPort::RackPort(devicenet::ScannerConfig port, const std::vector<PumpConfig>& pumps,
                   can::FrameSink& sink, Logger log,
                   const std::function<void(devicenet::ScannerConfig&)>& adjust)
    : in_force_(pumps), pumps_(pumps) {
  observers_.add(pumps_);
  auto scan_list = PumpRack::scanner_config(std::move(port), pumps);
  if (adjust) adjust(scan_list);
  scanner_.emplace(std::move(scan_list), sink, observers_, std::move(log));
  pumps_.attach(*scanner_);
}

ScanListChange RackPort::reconfigure(const devicenet::ScannerConfig& port,
                                     const std::vector<PumpConfig>& pumps, TimePoint now) {
  if (scanner_->state() == devicenet::PortState::kStopping) {
    throw std::runtime_error("the port is stopping");
  }
  // The whole checked before anything changes.
  devicenet::ScannerConfig next = PumpRack::scanner_config(port, pumps);
  next.master_mac = scanner_->config().master_mac;
  devicenet::Scanner::check(next);
  const ScanListChange change = compare(scanner_->config(), in_force_, next, pumps);
  const auto node_of = [&](MacId mac) {
    return *std::find_if(next.nodes.begin(), next.nodes.end(),
                         [&](const devicenet::NodeConfig& n) { return n.mac == mac; });
  };
  scanner_->retune(next);
  for (MacId mac : change.removed) {
    pumps_.remove(mac);
    (void)scanner_->remove_node(mac, now);
  }
  for (MacId mac : change.reconfigured) {
    pumps_.replace(*at(pumps, mac));
    (void)scanner_->remove_node(mac, now);
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.added) {
    pumps_.add(*at(pumps, mac));
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.updated) pumps_.update(*at(pumps, mac), now);
  in_force_ = pumps;
  return change;
}

}  // namespace dnbridge::rack
