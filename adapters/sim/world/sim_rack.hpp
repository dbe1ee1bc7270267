#pragma once
// A whole simulated rack port: the bus, the master with its rack models, a
// CDN127 per pump and a device driven by its EDS per device. Used by the
// integration tests and the demo.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "adapters/sim/world/sim_eds_slave.hpp"
#include "adapters/sim/world/sim_master.hpp"
#include "adapters/sim/world/sim_slave.hpp"
#include "adapters/sim/world/sim_world.hpp"
#include "bridge/rack/device_rack.hpp"
#include "bridge/rack/pump_rack.hpp"
#include "bridge/rack/rack_port.hpp"

namespace dnbridge::sim {

struct SimRackConfig {
  BusConfig bus{can::kBitrate500k};
  devicenet::ScannerConfig port;            // master MAC, timings; nodes come from the lists
  std::vector<rack::PumpConfig> pumps;      // the scan list: CDN127s
  std::vector<rack::DeviceConfig> devices;  // and devices described by their EDS
  bool create_devices = true;  // a CDN127 at each pump's MAC, an EdsSlave at each device's
  // Lets a test change the scan list the master is given after it is built
  // from `pumps` (e.g. a profile that disagrees with the device).
  std::function<void(devicenet::ScannerConfig&)> adjust_scan_list;
};

// The options of a simulated CDN127 at `mac` as it leaves the factory: MAC
// switch set to `mac`, serial number derived from it.
SlaveOptions default_slave_options(devicenet::MacId mac);
// The same for a simulated device driven by its EDS.
EdsSlaveOptions default_eds_slave_options(devicenet::MacId mac);

class SimRack {
 public:
  explicit SimRack(SimRackConfig config, LogSink* log = nullptr);
  SimRack(const SimRack&) = delete;
  SimRack& operator=(const SimRack&) = delete;

  SimWorld& world() { return world_; }
  TimePoint now() const { return world_.now(); }
  devicenet::Scanner& scanner() { return port_->scanner(); }
  SimMaster& master() { return *master_; }
  rack::PumpRack& pumps() { return port_->nodes<rack::PumpRack>(); }
  rack::DeviceRack& devices() { return port_->nodes<rack::DeviceRack>(); }
  // The master and the rack model together (a live reconfiguration).
  rack::RackPort& port() { return *port_; }
  // Extra observers (tests record events); add before start().
  void observe(devicenet::ScannerObserver& o) { port_->observe(o); }

  // A simulated device, powered on at `power_on` if given.
  SimSlave& add_device(SlaveOptions options, std::optional<TimePoint> power_on);
  SimSlave& device(devicenet::MacId mac);
  bool has_device(devicenet::MacId mac) const { return devices_.count(mac.value()) != 0; }
  // A simulated device driven by `file`, powered on at `power_on` if given.
  SimEdsSlave& add_eds_device(const profiles::eds::EdsFile& file, EdsSlaveOptions options,
                              std::optional<TimePoint> power_on);
  SimEdsSlave& eds_device(devicenet::MacId mac);

  // Powers on every device still off and starts the master, now.
  void start();
  bool all_online() const;

 private:
  SimRackConfig config_;
  LogSink* log_;
  SimWorld world_;
  std::optional<rack::RackPort> port_;  // the master and the rack model
  std::unique_ptr<SimMaster> master_;   // drives port_'s scanner on the bus
  std::map<unsigned, std::unique_ptr<SimSlave>> devices_;
  std::map<unsigned, std::unique_ptr<SimEdsSlave>> eds_devices_;
  bool started_ = false;
};

}  // namespace dnbridge::sim
