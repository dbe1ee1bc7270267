#pragma once
// One port of a rack, composed the one way it is everywhere (the daemon's
// port loop, dnbridge-sim, the benchmark, the simulated rack of the tests):
// the master (devicenet::Scanner) built from the scan list of the nodes of
// every profile (port_nodes.hpp), one model of the nodes per profile (its
// rack: PumpRack, DeviceRack, ...) hearing the master's events first, in
// the order of the profiles, then the observers added, in the order added.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/port_nodes.hpp"
#include "bridge/rack/profile_nodes.hpp"

namespace dnbridge::rack {

// What a new scan list changes in the one in force, node by node (by MAC,
// ascending in each list).
struct ScanListChange {
  std::vector<devicenet::MacId> added;
  std::vector<devicenet::MacId> removed;
  // Its device settings differ (I/O configuration, safe state, identity,
  // timings, serial; its EDS, parameters or connection; its profile):
  // released, then configured again.
  std::vector<devicenet::MacId> reconfigured;
  // Only what the bridge does with it differs (name, no-commander and
  // resume policies): applied in place, the node untouched.
  std::vector<devicenet::MacId> updated;
  std::vector<devicenet::MacId> unchanged;
  // The port's timings (devicenet::Scanner::same_timings).
  bool timings_changed = false;

  bool any() const {
    return timings_changed || !added.empty() || !removed.empty() || !reconfigured.empty() ||
           !updated.empty();
  }
};

ScanListChange compare(const devicenet::ScannerConfig& port_before, const PortNodes& before,
                       const devicenet::ScannerConfig& port_after, const PortNodes& after);

class RackPort {
 public:
  // `port`: the master's MAC and timings (its nodes come from `nodes`).
  // `adjust`: a change to the scan list after it is built (tests: a profile
  // that disagrees with the device). Throws std::invalid_argument for a scan
  // list the master refuses.
  RackPort(devicenet::ScannerConfig port, const PortNodes& nodes, can::FrameSink& sink, Logger log,
           const std::function<void(devicenet::ScannerConfig&)>& adjust = {});
  RackPort(const RackPort&) = delete;
  RackPort& operator=(const RackPort&) = delete;

  // Hears the master's events after the nodes' racks; add before the master
  // starts.
  void observe(devicenet::ScannerObserver& observer) { observers_.add(observer); }

  // Applies a new scan list and the port's timings while the port runs:
  // only what differs (compare()); nodes not named keep polling, untouched.
  // The master's MAC and duplicate MAC ID identity are not changed here.
  // Checks the whole first: throws std::invalid_argument, changing nothing,
  // for a scan list the master refuses.
  ScanListChange reconfigure(const devicenet::ScannerConfig& port, const PortNodes& nodes,
                             TimePoint now);

  // The master's scan list for `nodes` (the port's MAC and timings from
  // `port`). Throws std::invalid_argument for a node its profile refuses.
  static devicenet::ScannerConfig scan_list(devicenet::ScannerConfig port, const PortNodes& nodes);

  devicenet::Scanner& scanner() { return *scanner_; }
  const devicenet::Scanner& scanner() const { return *scanner_; }

  // The port's nodes of the profile whose rack is `Rack` (PumpRack,
  // DeviceRack, ...). Throws std::logic_error when the port has never had
  // a list of that profile.
  template <class Rack>
  Rack& nodes() {
    return const_cast<Rack&>(std::as_const(*this).nodes<Rack>());
  }
  template <class Rack>
  const Rack& nodes() const {
    for (ProfileNodes* p : profiles_) {
      if (const auto* r = dynamic_cast<const Rack*>(p)) return *r;
    }
    throw std::logic_error("the port has no nodes of the profile of " +
                           std::string(typeid(Rack).name()));
  }
  // Every profile's nodes, in the order they hear the master's events.
  std::span<ProfileNodes* const> profiles() const { return profiles_; }
  // The nodes of the profile the node at `mac` has; null when no node has it.
  ProfileNodes* nodes_of(devicenet::MacId mac) const;
  // The nodes whose view may have changed since the last call, of every
  // profile (ProfileNodes::take_changed); a bit per MAC. A removed node's
  // bit may be among them.
  std::uint64_t take_changed() noexcept {
    std::uint64_t changed = 0;
    for (ProfileNodes* p : profiles_) changed |= p->take_changed();
    return changed;
  }

 private:
  // The rack of `list`'s profile, made (empty, and attached) when the port
  // has none yet.
  ProfileNodes& rack_of(const NodeList& list);

  PortNodes in_force_;
  std::vector<std::unique_ptr<ProfileNodes>> racks_;
  std::vector<std::type_index> rack_lists_;  // the configuration type of each rack's nodes
  std::vector<ProfileNodes*> profiles_;      // racks_, as the layer above sees them
  devicenet::ObserverFanout observers_;      // the racks, then the observers added
  std::optional<devicenet::Scanner> scanner_;
};

}  // namespace dnbridge::rack
