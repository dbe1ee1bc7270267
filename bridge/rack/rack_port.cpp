#include "bridge/rack/rack_port.hpp"

#include <algorithm>
#include <stdexcept>

namespace dnbridge::rack {
namespace {

using devicenet::MacId;

// A node before and after: another profile is other device settings.
bool same_device_settings(const PortNodes::At& a, const PortNodes::At& b) {
  return a.list->same_device_settings(a.index, *b.list, b.index);
}

}  // namespace

ScanListChange compare(const devicenet::ScannerConfig& port_before, const PortNodes& before,
                       const devicenet::ScannerConfig& port_after, const PortNodes& after) {
  ScanListChange c;
  c.timings_changed = !devicenet::Scanner::same_timings(port_before, port_after);
  for (unsigned m = 0; m <= MacId::kMax; ++m) {
    const MacId mac = *MacId::from(m);
    const PortNodes::At was = before.at(mac);
    const PortNodes::At is = after.at(mac);
    if (!was && !is) continue;
    if (!was) {
      c.added.push_back(mac);
    } else if (!is) {
      c.removed.push_back(mac);
    } else if (!same_device_settings(was, is)) {
      c.reconfigured.push_back(mac);
    } else if (!was.list->same_handling(was.index, *is.list, is.index)) {
      c.updated.push_back(mac);
    } else {
      c.unchanged.push_back(mac);
    }
  }
  return c;
}

devicenet::ScannerConfig RackPort::scan_list(devicenet::ScannerConfig port,
                                             const PortNodes& nodes) {
  port.nodes.clear();
  for (const auto& list : nodes.lists()) {
    for (std::size_t i = 0; i < list->size(); ++i) port.nodes.push_back(list->scan_entry(i));
  }
  return port;
}

ProfileNodes* RackPort::nodes_of(MacId mac) const {
  for (ProfileNodes* nodes : profiles_) {
    if (nodes->node(mac) != nullptr) return nodes;
  }
  return nullptr;
}

ProfileNodes& RackPort::rack_of(const NodeList& list) {
  for (std::size_t i = 0; i < rack_lists_.size(); ++i) {
    if (rack_lists_[i] == list.type()) return *racks_[i];
  }
  racks_.push_back(list.make_rack());
  rack_lists_.push_back(list.type());
  profiles_.push_back(racks_.back().get());
  // After the racks there are, before the observers.
  observers_.insert(racks_.size() - 1, *racks_.back());
  if (scanner_) racks_.back()->attach(*scanner_);
  return *racks_.back();
}

RackPort::RackPort(devicenet::ScannerConfig port, const PortNodes& nodes, can::FrameSink& sink,
                   Logger log, const std::function<void(devicenet::ScannerConfig&)>& adjust)
    : in_force_(nodes) {
  for (const auto& list : nodes.lists()) {
    ProfileNodes& rack = rack_of(*list);
    for (std::size_t i = 0; i < list->size(); ++i) list->add(rack, i);
  }
  auto scan = scan_list(std::move(port), nodes);
  if (adjust) adjust(scan);
  scanner_.emplace(std::move(scan), sink, observers_, std::move(log));
  for (ProfileNodes* rack : profiles_) rack->attach(*scanner_);
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
    for (ProfileNodes* rack : profiles_) rack->remove(mac);
    (void)scanner_->remove_node(mac, now);
  }
  for (MacId mac : change.reconfigured) {
    // In its place when its profile stays, anew in the other rack when not.
    const PortNodes::At is = nodes.at(mac);
    ProfileNodes& rack = rack_of(*is.list);
    for (ProfileNodes* other : profiles_) {
      if (other != &rack) other->remove(mac);
    }
    is.list->replace(rack, is.index);
    (void)scanner_->remove_node(mac, now);
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.added) {
    const PortNodes::At is = nodes.at(mac);
    is.list->add(rack_of(*is.list), is.index);
    (void)scanner_->add_node(node_of(mac), now);
  }
  for (MacId mac : change.updated) {
    const PortNodes::At is = nodes.at(mac);
    is.list->update(rack_of(*is.list), is.index, now);
  }
  in_force_ = nodes;
  return change;
}

}  // namespace dnbridge::rack
