#include "adapters/daemon/simulated_backends.hpp"

#include <vector>

#include "adapters/sim/world/sim_backend.hpp"

namespace dnbridge::daemon {

BackendFactory simulated_backend_factory(LogSink& log) {
  return [&log, others = default_backend_factory(log)](
             const PortConfig& p) -> std::unique_ptr<port::CanBackend> {
    if (p.interface != kSimulatedInterface) return others(p);
    std::vector<devicenet::MacId> macs;
    std::vector<sim::EdsDeviceSpec> eds_devices;
    for (const auto& n : p.nodes) {
      if (n.is_eds()) {
        eds_devices.push_back({n.pump.node.mac, n.eds});
      } else {
        macs.push_back(n.pump.node.mac);
      }
    }
    // Devices the configuration does not have: powered up with the others,
    // they are heard checking their MAC ID, and never polled.
    for (const auto mac : p.simulated_unconfigured) macs.push_back(mac);
    return std::make_unique<sim::SimBackend>(p.bitrate, macs, &log, eds_devices);
  };
}

}  // namespace dnbridge::daemon
