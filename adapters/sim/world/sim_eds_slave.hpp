#pragma once
// A simulated device driven by its EDS file (EdsSlave) on the simulated bus.
#include <optional>

#include "adapters/sim/generic/eds_slave.hpp"
#include "adapters/sim/world/sim_device.hpp"

namespace dnbridge::sim {

class SimEdsSlave final : public SimDevice<EdsSlave> {
 public:
  // Attaches to the world's bus; the device powers up at `power_on` (no
  // value: stays off until power_on() is called).
  SimEdsSlave(SimWorld& world, profiles::eds::EdsFile file, EdsSlaveOptions options,
              std::optional<TimePoint> power_on, Logger log = {})
      : SimDevice(world) {
    build(power_on, std::move(file), options, std::move(log));
  }
};

}  // namespace dnbridge::sim
