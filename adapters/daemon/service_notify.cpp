#include "adapters/daemon/service_notify.hpp"

#include <fmt/format.h>
#include <systemd/sd-daemon.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <vector>

#include "adapters/daemon/watchdog.hpp"
#include "adapters/port/steady_time.hpp"
#include "adapters/port/thread_name.hpp"

namespace dnbridge::daemon {
namespace {

// How often readiness and the status line are looked at.
constexpr Duration kTick = milliseconds(250);
// A port loop wakes at least once per status period (1 s); a watchdog check
// interval shorter than this (1 s and a margin) would take an idle loop for
// a stalled one.
constexpr Duration kLongestLoopSleep = milliseconds(1500);
// The loops are checked every half period (WATCHDOG_USEC / 2): the
// shortest WatchdogSec= that does not take idle loops for stalled ones.
constexpr Duration kShortestWatchdog = 2 * kLongestLoopSleep;

void notify(const std::string& state) { sd_notify(0, state.c_str()); }

}  // namespace

std::string service_status(std::span<const PortSummary> ports) {
  bool all_started = true;
  unsigned online = 0;
  std::size_t configured = 0;
  std::string per_port;
  for (const auto& p : ports) {
    all_started = all_started && p.started_up;
    online += p.nodes_online;
    configured += p.nodes_configured;
    std::string trouble = p.stalled ? "loop stalled" : "";
    if (!p.problem.empty()) trouble += (trouble.empty() ? "" : "; ") + p.problem;
    per_port += fmt::format("{}{} {}/{}{}{}", per_port.empty() ? "" : ", ", p.name, p.nodes_online,
                            p.nodes_configured, trouble.empty() ? "" : ": ", trouble);
  }
  return fmt::format("{}{}/{} nodes online ({})", all_started ? "" : "start-up checks: ", online,
                     configured, per_port);
}

ServiceNotifier::ServiceNotifier(const Daemon& daemon, Logger log)
    : daemon_(daemon), log_(std::move(log)) {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  enabled_ = socket != nullptr && *socket != '\0';
}

ServiceNotifier::~ServiceNotifier() { join(); }

void ServiceNotifier::start() {
  if (!enabled_ || thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, "sd_notify");
}

void ServiceNotifier::join() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ServiceNotifier::stopping() {
  join();
  if (enabled_) notify("STOPPING=1\nSTATUS=stopping: idling and releasing every node");
}

void ServiceNotifier::run() {
  // WATCHDOG_USEC (and WATCHDOG_PID, if set, naming this process): fed at
  // half the period, as sd_watchdog_enabled(3) advises.
  std::uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  const Duration interval = std::chrono::microseconds(watchdog_usec / 2);
  if (watchdog && std::chrono::microseconds(watchdog_usec) < kShortestWatchdog) {
    log_.warn(
        "WatchdogSec={} ms is too short: the port loops are checked every half period, and an "
        "idle one may go {:g} s without a round; use {:g} s or more",
        watchdog_usec / 1000, std::chrono::duration<double>(kLongestLoopSleep).count(),
        std::chrono::duration<double>(kShortestWatchdog).count());
  }

  const auto& ports = daemon_.ports();
  std::vector<std::uint64_t> progress(ports.size());
  const auto read_progress = [&] {
    for (std::size_t i = 0; i < ports.size(); ++i) progress[i] = ports[i]->heartbeat();
  };
  read_progress();
  std::optional<LoopWatchdog> dog;
  if (watchdog) {
    std::vector<std::string> names;
    for (const auto& p : ports) names.push_back(p->name());
    dog.emplace(std::move(names), interval, port::steady_now(), progress, log_);
  }

  std::vector<PortSummary> summary(ports.size());
  bool ready = false;
  std::string last_status;
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const TimePoint now = port::steady_now();
    if (dog) {
      read_progress();
      if (dog->check(now, progress)) notify("WATCHDOG=1");
    }
    for (std::size_t i = 0; i < ports.size(); ++i) {
      const auto& p = *ports[i];
      PortSummary& s = summary[i];
      s.name = p.name();
      s.started_up = p.started_up();
      s.nodes_online = p.nodes_online();
      s.nodes_configured = p.nodes_configured();
      s.problem = p.problem();
      s.stalled = dog && dog->stalled(i);
    }
    const std::string status = service_status(summary);
    const bool all_started = std::all_of(summary.begin(), summary.end(),
                                         [](const PortSummary& s) { return s.started_up; });
    if (!ready && all_started) {
      notify(fmt::format("READY=1\nSTATUS={}", status));
      ready = true;
      last_status = status;
    } else if (status != last_status) {
      notify(fmt::format("STATUS={}", status));
      last_status = status;
    }
    TimePoint wake = now + kTick;
    if (dog) wake = std::min(wake, dog->next_check());
    wake_.wait_until(lock, port::to_steady(wake), [this] { return stop_; });
  }
}

}  // namespace dnbridge::daemon
