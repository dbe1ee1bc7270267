#include "adapters/sim/world/sim_master.hpp"

namespace dnbridge::sim {

SimMaster::SimMaster(SimWorld& world, devicenet::ScannerConfig config,
                     devicenet::ScannerObserver& observer, Logger log)
    : SimMaster(world, [&](can::FrameSink& sink) -> devicenet::Scanner& {
        return own_.emplace(std::move(config), sink, observer, std::move(log));
      }) {}

SimMaster::SimMaster(SimWorld& world,
                     const std::function<devicenet::Scanner&(can::FrameSink& sink)>& build)
    : world_(world), handle_(world.bus().attach(*this)) {
  try {
    scanner_ = &build(world.bus().sink(handle_));
  } catch (...) {
    (void)world_.bus().detach(handle_);  // the bus must not keep an endpoint that never was
    throw;
  }
  world_.add(*this);
}

SimMaster::~SimMaster() {
  world_.remove(*this);
  (void)world_.bus().detach(handle_);
}

void SimMaster::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  scanner_->on_frame(frame, rx_time);
}

}  // namespace dnbridge::sim
