#pragma once
// One deterministic loop over a simulated bus and everything attached to it:
// the lely-style "master and slaves on an in-process bus, driven by one
// loop". Time is virtual: it jumps from one event to the next, so a test of
// minutes of bus time runs in milliseconds and always the same way.
#include <cstddef>
#include <functional>
#include <vector>

#include "adapters/sim/bus/virtual_bus.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::sim {

// Something on the bus that also needs time: a master's port, a slave.
class SimEndpoint : public BusPort {
 public:
  virtual TimePoint next_deadline() const = 0;
  virtual void on_timer(TimePoint now) = 0;
};

class SimWorld {
 public:
  explicit SimWorld(BusConfig config = {}, TimePoint start = TimePoint{} + seconds(1));
  SimWorld(const SimWorld&) = delete;
  SimWorld& operator=(const SimWorld&) = delete;

  VirtualBus& bus() { return bus_; }
  const VirtualBus& bus() const { return bus_; }
  TimePoint now() const { return now_; }

  // Adds an endpoint that is already attached to the bus (endpoints attach
  // themselves, since they need their FrameSink at construction).
  void add(SimEndpoint& endpoint);
  void remove(SimEndpoint& endpoint);

  // The next time something happens (kNever when nothing will).
  TimePoint next_event() const;
  // Handles everything due at the next event time, if that is <= limit;
  // returns false (time unchanged) otherwise.
  bool step(TimePoint limit);
  // Runs every event up to `until`, then sets the time to `until`.
  void run_until(TimePoint until);
  void run_for(Duration d) { run_until(now_ + d); }
  // Runs until `done()` holds (checked after every step) or `timeout` passes;
  // returns whether it holds.
  bool run_until(const std::function<bool()>& done, Duration timeout);

 private:
  VirtualBus bus_;
  std::vector<SimEndpoint*> endpoints_;
  TimePoint now_;
  std::size_t same_time_steps_ = 0;
};

}  // namespace dnbridge::sim
