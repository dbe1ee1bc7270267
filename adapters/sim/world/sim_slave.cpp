#include "adapters/sim/world/sim_slave.hpp"

namespace dnbridge::sim {

SimSlave::SimSlave(SimWorld& world, SlaveOptions options, std::optional<TimePoint> power_on,
                   Logger log)
    : world_(world), handle_(world.bus().attach(*this)) {
  slave_.emplace(world.bus().sink(handle_), std::move(options), std::move(log));
  world_.add(*this);
  if (power_on) slave_->power_on(*power_on);
}

SimSlave::~SimSlave() {
  world_.remove(*this);
  (void)world_.bus().detach(handle_);
}

void SimSlave::disconnect() { (void)world_.bus().detach(handle_); }
void SimSlave::reconnect() { (void)world_.bus().reattach(handle_); }

void SimSlave::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  slave_->on_frame(frame, rx_time);
}

TimePoint SimSlave::next_deadline() const { return slave_->next_deadline(); }

}  // namespace dnbridge::sim
