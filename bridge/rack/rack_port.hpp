#pragma once
// One port of a rack, composed the one way it is everywhere (the daemon's
// port loop, dnbridge-sim, the benchmark, the simulated rack of the tests):
// the master (devicenet::Scanner) built from the pumps' scan list, the rack
// model (PumpRack) hearing the master's events first, then the observers
// added, in the order added.
#include <functional>
#include <optional>
#include <vector>

#include "bridge/can/frame_sink.hpp"
#include "bridge/common/log.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::rack {

class RackPort {
 public:
  // `port`: the master's MAC and timings (its nodes come from `pumps`).
  // `adjust`: a change to the scan list after it is built (tests: a profile
  // that disagrees with the device). Throws std::invalid_argument for a scan
  // list the master refuses.
  RackPort(devicenet::ScannerConfig port, const std::vector<PumpConfig>& pumps,
           can::FrameSink& sink, Logger log,
           const std::function<void(devicenet::ScannerConfig&)>& adjust = {});
  RackPort(const RackPort&) = delete;
  RackPort& operator=(const RackPort&) = delete;

  // Hears the master's events after the rack model; add before the master
  // starts.
  void observe(devicenet::ScannerObserver& observer) { observers_.add(observer); }

  devicenet::Scanner& scanner() { return *scanner_; }
  const devicenet::Scanner& scanner() const { return *scanner_; }
  PumpRack& pumps() { return pumps_; }
  const PumpRack& pumps() const { return pumps_; }

 private:
  PumpRack pumps_;
  devicenet::ObserverFanout observers_;
  std::optional<devicenet::Scanner> scanner_;
};

}  // namespace dnbridge::rack
