#pragma once
// A simulated device on the simulated bus: the endpoint that joins a
// sans-IO slave (Cdn127Slave, EdsSlave) to the world's bus and clock.
#include <optional>
#include <utility>

#include "adapters/sim/world/sim_world.hpp"

namespace dnbridge::sim {

template <class Device>
class SimDevice : public SimEndpoint {
 public:
  ~SimDevice() override {
    world_.remove(*this);
    (void)world_.bus().detach(handle_);
  }
  SimDevice(const SimDevice&) = delete;
  SimDevice& operator=(const SimDevice&) = delete;

  Device& device() { return *slave_; }
  const Device& device() const { return *slave_; }
  NodeHandle handle() const { return handle_; }
  void power_on(TimePoint now) { slave_->power_on(now); }
  // Off the bus (cable pulled); reconnect() puts it back as it was.
  void disconnect() { (void)world_.bus().detach(handle_); }
  void reconnect() { (void)world_.bus().reattach(handle_); }

  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override {
    slave_->on_frame(frame, rx_time);
  }
  TimePoint next_deadline() const override { return slave_->next_deadline(); }
  void on_timer(TimePoint now) override { slave_->on_timer(now); }

 protected:
  explicit SimDevice(SimWorld& world) : world_(world), handle_(world.bus().attach(*this)) {}
  // Builds the device on the bus (its sink first, then `args`); it powers up
  // at `power_on` (no value: stays off until power_on() is called).
  template <class... Args>
  void build(std::optional<TimePoint> power_on, Args&&... args) {
    slave_.emplace(world_.bus().sink(handle_), std::forward<Args>(args)...);
    world_.add(*this);
    if (power_on) slave_->power_on(*power_on);
  }

 private:
  SimWorld& world_;
  NodeHandle handle_;
  std::optional<Device> slave_;
};

}  // namespace dnbridge::sim
