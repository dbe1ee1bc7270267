#pragma once
// A simulated CDN127 on the simulated bus.
#include <optional>

#include "adapters/sim/cdn127/cdn127_slave.hpp"
#include "adapters/sim/world/sim_world.hpp"

namespace dnbridge::sim {

class SimSlave final : public SimEndpoint {
 public:
  // Attaches to the world's bus; the device powers up at `power_on` (no
  // value: stays off until power_on() is called).
  SimSlave(SimWorld& world, SlaveOptions options, std::optional<TimePoint> power_on,
           Logger log = {});
  ~SimSlave() override;
  SimSlave(const SimSlave&) = delete;
  SimSlave& operator=(const SimSlave&) = delete;

  Cdn127Slave& device() { return *slave_; }
  const Cdn127Slave& device() const { return *slave_; }
  NodeHandle handle() const { return handle_; }

  void power_on(TimePoint now) { slave_->power_on(now); }
  // Off the bus (cable pulled); reconnect() puts it back as it was.
  void disconnect();
  void reconnect();

  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override;
  TimePoint next_deadline() const override;
  void on_timer(TimePoint now) override { slave_->on_timer(now); }

 private:
  SimWorld& world_;
  NodeHandle handle_;
  std::optional<Cdn127Slave> slave_;
};

}  // namespace dnbridge::sim
