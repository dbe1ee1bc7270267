#include "adapters/daemon/watchdog.hpp"

#include <chrono>

namespace dnbridge::daemon {
namespace {

long long ms(Duration d) { return std::chrono::duration_cast<milliseconds>(d).count(); }

}  // namespace

LoopWatchdog::LoopWatchdog(std::vector<std::string> ports, Duration interval, TimePoint now,
                           std::span<const std::uint64_t> progress, Logger log)
    : interval_(interval), next_check_(now + interval), log_(std::move(log)) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    loops_.push_back(Loop{std::move(ports[i]), i < progress.size() ? progress[i] : 0, now, false});
  }
}

bool LoopWatchdog::check(TimePoint now, std::span<const std::uint64_t> progress) {
  if (now < next_check_) return false;
  // On a grid of whole intervals; a caller late by more than one starts a
  // new grid rather than checking twice in a row.
  next_check_ += interval_;
  if (next_check_ <= now) next_check_ = now + interval_;

  bool all_advanced = progress.size() == loops_.size();
  for (std::size_t i = 0; i < loops_.size() && i < progress.size(); ++i) {
    Loop& loop = loops_[i];
    const bool advanced = progress[i] != loop.progress;
    loop.progress = progress[i];
    if (advanced) {
      if (loop.stalled) {
        log_.warn("port {}: loop advances again, after {} ms without progress", loop.name,
                  ms(now - loop.advanced));
      }
      loop.stalled = false;
      loop.advanced = now;
      continue;
    }
    all_advanced = false;
    if (!loop.stalled) {
      loop.stalled = true;
      log_.error(
          "port {}: loop stalled (no progress in {} ms): the watchdog is no longer fed, and "
          "systemd restarts the service when WatchdogSec= runs out",
          loop.name, ms(now - loop.advanced));
    }
  }
  return all_advanced;
}

}  // namespace dnbridge::daemon
