#pragma once
// A simulated CDN127 on the simulated bus.
#include <optional>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "adapters/sim/world/sim_device.hpp"

namespace dnbridge::sim {

class SimSlave final : public SimDevice<Cdn127Slave> {
 public:
  // Attaches to the world's bus; the device powers up at `power_on` (no
  // value: stays off until power_on() is called).
  SimSlave(SimWorld& world, SlaveOptions options, std::optional<TimePoint> power_on,
           Logger log = {})
      : SimDevice(world) {
    build(power_on, std::move(options), std::move(log));
  }
};

}  // namespace dnbridge::sim
