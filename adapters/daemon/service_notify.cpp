#include "adapters/daemon/service_notify.hpp"

#include <fmt/format.h>
#include <systemd/sd-daemon.h>

#include <chrono>
#include <cstdlib>
#include <vector>

namespace dnbridge::daemon {
namespace {

// How often readiness and the status line are looked at.
constexpr auto kTick = std::chrono::milliseconds(250);
// A port loop wakes at least once per status period (1 s); a watchdog check
// interval shorter than this would take an idle loop for a stalled one.
constexpr auto kLongestLoopSleep = std::chrono::milliseconds(1500);

void notify(const std::string& state) { sd_notify(0, state.c_str()); }

}  // namespace

ServiceNotifier::ServiceNotifier(const Daemon& daemon, Logger log)
    : daemon_(daemon), log_(std::move(log)) {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  enabled_ = socket != nullptr && *socket != '\0';
}

ServiceNotifier::~ServiceNotifier() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ServiceNotifier::start() {
  if (!enabled_ || thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

void ServiceNotifier::stopping() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (enabled_) notify("STOPPING=1\nSTATUS=stopping: idling and releasing every node");
}

void ServiceNotifier::run() {
  using Clock = std::chrono::steady_clock;
  std::uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  const auto check_period = std::chrono::microseconds(watchdog_usec / 2);
  if (watchdog && check_period < kLongestLoopSleep) {
    log_.warn("WatchdogSec={} ms is too short for port loops that sleep up to 1 s; use 4 s or more",
              watchdog_usec / 1000);
  }
  const auto& ports = daemon_.ports();
  std::vector<std::uint64_t> beats(ports.size());
  for (std::size_t i = 0; i < ports.size(); ++i) beats[i] = ports[i]->heartbeat();
  auto next_check = Clock::now() + check_period;
  bool ready = false;
  std::string last_status;

  std::unique_lock lock(mutex_);
  while (!stop_) {
    bool all_started = true;
    unsigned online = 0;
    std::size_t configured = 0;
    std::string per_port;
    for (const auto& p : ports) {
      all_started = all_started && p->started_up();
      online += p->nodes_online();
      configured += p->nodes_configured();
      per_port += fmt::format("{}{} {}/{}", per_port.empty() ? "" : ", ", p->name(),
                              p->nodes_online(), p->nodes_configured());
    }
    std::string status =
        fmt::format("{}{}/{} nodes online ({})", all_started ? "" : "start-up checks: ", online,
                    configured, per_port);
    if (!ready && all_started) {
      notify(fmt::format("READY=1\nSTATUS={}", status));
      ready = true;
      last_status = status;
    } else if (status != last_status) {
      notify(fmt::format("STATUS={}", status));
      last_status = status;
    }

    if (watchdog && Clock::now() >= next_check) {
      // Fed only if every loop went round since the last check: one stalled
      // loop starves the watchdog, and systemd restarts the service.
      bool alive = true;
      for (std::size_t i = 0; i < ports.size(); ++i) {
        const std::uint64_t beat = ports[i]->heartbeat();
        if (beat == beats[i]) {
          alive = false;
          log_.error("port {}: loop stalled, watchdog not fed", ports[i]->name());
        }
        beats[i] = beat;
      }
      if (alive) notify("WATCHDOG=1");
      next_check += check_period;
    }
    wake_.wait_for(lock, kTick, [this] { return stop_; });
  }
}

}  // namespace dnbridge::daemon
