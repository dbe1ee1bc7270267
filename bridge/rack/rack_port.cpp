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

bool same_device_settings(const DeviceConfig& a, const DeviceConfig& b) {
  devicenet::NodeConfig na = a.node;
  devicenet::NodeConfig nb = b.node;
  na.name.clear();
  nb.name.clear();
  return na == nb && a.eds_digest == b.eds_digest && a.settings == b.settings;
}

template <class Config>
bool same_handling(const Config& a, const Config& b) {
  return a.node.name == b.node.name && a.no_commander == b.no_commander && a.resume == b.resume &&
         a.command_refresh == b.command_refresh;
}

template <class Config>
const Config* at(const std::vector<Config>& configs, MacId mac) {
  auto it = std::find_if(configs.begin(), configs.end(),
                         [&](const Config& c) { return c.node.mac == mac; });
  return it == configs.end() ? nullptr : &*it;
}

// A node in one of the lists, or none.
struct Found {
  const PumpConfig* pump = nullptr;
  const DeviceConfig* device = nullptr;
  explicit operator bool() const { return pump != nullptr || device != nullptr; }
};

// A node before and after: another profile is other device settings.
bool same_device_settings(const Found& a, const Found& b) {
  if (a.pump && b.pump) return same_device_settings(*a.pump, *b.pump);
  if (a.device && b.device) return same_device_settings(*a.device, *b.device);
  return false;
}

// A node before and after, with the same device settings (so the same profile).
bool same_handling(const Found& a, const Found& b) {
  return a.pump ? same_handling(*a.pump, *b.pump) : same_handling(*a.device, *b.device);
}

Found at(const PortNodes& nodes, MacId mac) {
  return {at(nodes.pumps, mac), at(nodes.devices, mac)};
}

}  // namespace

ScanListChange compare(const devicenet::ScannerConfig& port_before, const PortNodes& before,
                       const devicenet::ScannerConfig& port_after, const PortNodes& after) {
  ScanListChange c;
  c.timings_changed = !devicenet::Scanner::same_timings(port_before, port_after);
  for (unsigned m = 0; m <= MacId::kMax; ++m) {
    const MacId mac = *MacId::from(m);
    const Found was = at(before, mac);
    const Found is = at(after, mac);
    if (!was && !is) continue;
    if (!was) {
      c.added.push_back(mac);
    } else if (!is) {
      c.removed.push_back(mac);
    } else if (!same_device_settings(was, is)) {
      c.reconfigured.push_back(mac);
    } else if (!same_handling(was, is)) {
      c.updated.push_back(mac);
    } else {
      c.unchanged.push_back(mac);
    }
  }
  return c;
}

devicenet::ScannerConfig RackPort::scan_list(devicenet::ScannerConfig port,
                                             const PortNodes& nodes) {
  return DeviceRack::scanner_config(PumpRack::scanner_config(std::move(port), nodes.pumps),
                                    nodes.devices);
}

ProfileNodes* RackPort::nodes_of(MacId mac) const {
  for (ProfileNodes* nodes : profiles_) {
    if (nodes->node(mac) != nullptr) return nodes;
  }
  return nullptr;
}

RackPort::RackPort(devicenet::ScannerConfig port, const PortNodes& nodes, can::FrameSink& sink,
                   Logger log, const std::function<void(devicenet::ScannerConfig&)>& adjust)
    : in_force_(nodes), pumps_(nodes.pumps), devices_(nodes.devices) {
  for (ProfileNodes* profile : profiles_) observers_.add(*profile);
  auto list = scan_list(std::move(port), nodes);
  if (adjust) adjust(list);
  scanner_.emplace(std::move(list), sink, observers_, std::move(log));
  pumps_.attach(*scanner_);
  devices_.attach(*scanner_);
}

ScanListChange RackPort::reconfigure(const devicenet::ScannerConfig& port, const PortNodes& nodes,
                                     TimePoint now) {
  if (scanner_->state() == devicenet::PortState::kStopping) {
    throw std::runtime_error("the port is stopping");
  }
  // The whole checked before anything changes.
  devicenet::ScannerConfig next = scan_list(port, nodes);
  next.master_mac = scanner_->config().master_mac;
  devicenet::Scanner::check(next);
  ScanListChange change = compare(scanner_->config(), in_force_, next, nodes);
  const auto node_of = [&](MacId mac) {
    return *std::find_if(next.nodes.begin(), next.nodes.end(),
                         [&](const devicenet::NodeConfig& n) { return n.mac == mac; });
  };
  scanner_->retune(next);
  for (MacId mac : change.removed) {
    pumps_.remove(mac);
    devices_.remove(mac);
    (void)scanner_->remove_node(mac, now);
  }
  for (MacId mac : change.reconfigured) {
    // In its place when its profile stays, anew in the other rack when not.
    const Found is = at(nodes, mac);
    if (is.pump) {
      devices_.remove(mac);
      pumps_.replace(*is.pump);
    } else if (is.device) {
      pumps_.remove(mac);
      devices_.replace(*is.device);
    }
    (void)scanner_->remove_node(mac, now);
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.added) {
    const Found is = at(nodes, mac);
    if (is.pump) pumps_.add(*is.pump);
    if (is.device) devices_.add(*is.device);
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.updated) {
    const Found is = at(nodes, mac);
    if (is.pump) pumps_.update(*is.pump, now);
    if (is.device) devices_.update(*is.device, now);
  }
  in_force_ = nodes;
  return change;
}

}  // namespace dnbridge::rack
