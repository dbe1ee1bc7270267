#pragma once
// When dnbridge feeds systemd's watchdog (WATCHDOG=1, dnbridge@.service's
// WatchdogSec=): once per check interval (WATCHDOG_USEC / 2, as
// sd_watchdog_enabled(3) advises), and only if every port loop went round
// since the previous check. A loop that stops advancing starves the watchdog
// and systemd restarts the service; one that advances again is fed for again.
//
// No clock and no system calls: the caller hands in the time and each loop's
// progress counter (port::PortLoop::heartbeat()), so tests drive it with a
// fake clock.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::daemon {

class LoopWatchdog {
 public:
  // `ports` names the loops in the order of every `progress` below, which
  // holds their counters as of `now`. The first check is `interval` later.
  LoopWatchdog(std::vector<std::string> ports, Duration interval, TimePoint now,
               std::span<const std::uint64_t> progress, Logger log);

  TimePoint next_check() const { return next_check_; }

  // Before next_check(): false, and nothing changes. From then on, once per
  // interval: true (send WATCHDOG=1) when every counter moved since the
  // previous check. A loop whose counter did not is logged as an error when
  // it stops and as a warning when it advances again, once each.
  bool check(TimePoint now, std::span<const std::uint64_t> progress);

  // Whether loop `i` had not advanced at the last check.
  bool stalled(std::size_t i) const { return loops_.at(i).stalled; }

 private:
  struct Loop {
    std::string name;
    std::uint64_t progress = 0;  // at the previous check
    TimePoint advanced{};        // the last check that saw it advance
    bool stalled = false;
  };

  std::vector<Loop> loops_;
  Duration interval_;
  TimePoint next_check_;
  Logger log_;
};

}  // namespace dnbridge::daemon
