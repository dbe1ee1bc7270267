#pragma once
// A port's bus figures for PortStatus: frames per second, bus load and scan
// cycle, measured over whole status periods. They are measured as a
// PortStatus is made (measure_if_due), never on their own: a PortStatus
// that comes between two measurements (a change of state) carries the last
// measured figures, and the period keeps its length.
#include <array>
#include <cstdint>
#include <span>

#include "adapters/port/can_backend.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"

namespace dnbridge::port {

class BusMetrics {
 public:
  struct Figures {
    double frames_per_second = 0;
    double bus_load_percent = 0;
    double scan_cycle_ms = 0;  // mean interval between two polls of an online node
  };
  // A node's polls so far, as the master counts them (devicenet::NodeCounters::polls).
  struct NodePolls {
    devicenet::MacId mac;
    bool online = false;
    std::uint64_t polls = 0;
  };

  explicit BusMetrics(Duration period) : period_(period) {}

  // The first period begins.
  void start(TimePoint now) { since_ = now; }
  // Measures over the time since the last measurement when a whole period
  // has passed by `now`; nothing otherwise. `bitrate` 0: no bus load.
  void measure_if_due(const BusCounters& bus, std::uint32_t bitrate,
                      std::span<const NodePolls> nodes, TimePoint now);
  // The node at `mac` starts counting its polls anew (added, or configured
  // again, by a reload).
  void restart(devicenet::MacId mac) { polls_[mac.value()] = 0; }

  const Figures& figures() const { return figures_; }

 private:
  Duration period_;
  TimePoint since_{};
  BusCounters last_{};
  std::array<std::uint64_t, devicenet::MacId::kMax + 1> polls_{};  // at the last measurement
  Figures figures_;
};

}  // namespace dnbridge::port
