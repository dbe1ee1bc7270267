#include "adapters/port/bus_metrics.hpp"

#include <chrono>

namespace dnbridge::port {

void BusMetrics::measure_if_due(const BusCounters& bus, std::uint32_t bitrate,
                                std::span<const NodePolls> nodes, TimePoint now) {
  if (now - since_ < period_) return;
  const double elapsed = std::chrono::duration<double>(now - since_).count();
  double cycle_sum = 0;
  unsigned cycles = 0;
  for (const NodePolls& n : nodes) {
    std::uint64_t& last = polls_[n.mac.value()];
    if (n.online && n.polls > last) {
      cycle_sum += 1000.0 * elapsed / static_cast<double>(n.polls - last);
      ++cycles;
    }
    last = n.polls;
  }
  figures_.frames_per_second = static_cast<double>(bus.frames - last_.frames) / elapsed;
  figures_.bus_load_percent = bitrate ? 100.0 * static_cast<double>(bus.bits - last_.bits) /
                                            (static_cast<double>(bitrate) * elapsed)
                                      : 0.0;
  figures_.scan_cycle_ms = cycles ? cycle_sum / cycles : 0.0;
  last_ = bus;
  since_ = now;
}

}  // namespace dnbridge::port
