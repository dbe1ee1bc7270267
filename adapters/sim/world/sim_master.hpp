#pragma once
// The master's port on the simulated bus: a Scanner attached as one node.
#include <functional>
#include <memory>
#include <optional>

#include "adapters/sim/world/sim_world.hpp"
#include "bridge/devicenet/master/scanner.hpp"

namespace dnbridge::sim {

class SimMaster final : public SimEndpoint {
 public:
  SimMaster(SimWorld& world, devicenet::ScannerConfig config, devicenet::ScannerObserver& observer,
            Logger log = {});
  // The scanner `build` makes with the master's sink on the bus (a
  // rack::RackPort's, for one), driven by this endpoint; it must outlive it.
  SimMaster(SimWorld& world, const std::function<devicenet::Scanner&(can::FrameSink& sink)>& build);
  ~SimMaster() override;

  devicenet::Scanner& scanner() { return *scanner_; }
  const devicenet::Scanner& scanner() const { return *scanner_; }
  NodeHandle handle() const { return handle_; }

  void on_frame(const can::CanFrame& frame, TimePoint rx_time) override;
  TimePoint next_deadline() const override { return scanner_->next_deadline(); }
  void on_timer(TimePoint now) override { scanner_->on_timer(now); }

 private:
  SimWorld& world_;
  NodeHandle handle_;
  std::optional<devicenet::Scanner> own_;  // built by the first constructor
  devicenet::Scanner* scanner_ = nullptr;
};

}  // namespace dnbridge::sim
