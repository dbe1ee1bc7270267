#pragma once
// One port of a rack, composed the one way it is everywhere (the daemon's
// port loop, dnbridge-sim, the benchmark, the simulated rack of the tests):
// the master (devicenet::Scanner) built from the scan list of the pumps
// (CDN127s) and the devices described by their EDS files, the rack models
// (PumpRack, then DeviceRack) hearing the master's events first, then the
// observers added, in the order added.
#include <array>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/pump_rack.hpp"

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

// The nodes of a port's scan list, by profile.
struct PortNodes {
  std::vector<PumpConfig> pumps;
  std::vector<DeviceConfig> devices;
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
  // Pumps only.
  RackPort(devicenet::ScannerConfig port, const std::vector<PumpConfig>& pumps,
           can::FrameSink& sink, Logger log,
           const std::function<void(devicenet::ScannerConfig&)>& adjust = {})
      : RackPort(std::move(port), PortNodes{pumps, {}}, sink, std::move(log), adjust) {}
  RackPort(const RackPort&) = delete;
  RackPort& operator=(const RackPort&) = delete;

  // Hears the master's events after the rack model; add before the master
  // starts.
  void observe(devicenet::ScannerObserver& observer) { observers_.add(observer); }

  // Applies a new scan list and the port's timings while the port runs:
  // only what differs (compare()); nodes not named keep polling, untouched.
  // The master's MAC and duplicate MAC ID identity are not changed here.
  // Checks the whole first: throws std::invalid_argument, changing nothing,
  // for a scan list the master refuses.
  ScanListChange reconfigure(const devicenet::ScannerConfig& port, const PortNodes& nodes,
                             TimePoint now);
  // Pumps only.
  ScanListChange reconfigure(const devicenet::ScannerConfig& port,
                             const std::vector<PumpConfig>& pumps, TimePoint now) {
    return reconfigure(port, PortNodes{pumps, {}}, now);
  }

  // The master's scan list for `nodes` (the port's MAC and timings from
  // `port`). Throws std::invalid_argument for a node its profile refuses.
  static devicenet::ScannerConfig scan_list(devicenet::ScannerConfig port, const PortNodes& nodes);

  devicenet::Scanner& scanner() { return *scanner_; }
  const devicenet::Scanner& scanner() const { return *scanner_; }
  PumpRack& pumps() { return pumps_; }
  const PumpRack& pumps() const { return pumps_; }
  DeviceRack& devices() { return devices_; }
  const DeviceRack& devices() const { return devices_; }
  // Every profile's nodes, in the order they hear the master's events.
  std::span<ProfileNodes* const> profiles() const { return profiles_; }
  // The nodes of the profile the node at `mac` has; null when no node has it.
  ProfileNodes* nodes_of(devicenet::MacId mac) const;

 private:
  PortNodes in_force_;
  PumpRack pumps_;
  DeviceRack devices_;
  std::array<ProfileNodes*, 2> profiles_{&pumps_, &devices_};
  devicenet::ObserverFanout observers_;
  std::optional<devicenet::Scanner> scanner_;
};

}  // namespace dnbridge::rack
