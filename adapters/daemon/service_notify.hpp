#pragma once
// The daemon's side of systemd's notify protocol (sd_notify(3)), for
// dnbridge@.service (Type=notify, WatchdogSec=): READY=1 once every port has
// finished its start-up checks, STATUS= with the nodes online and what is
// wrong with each port, WATCHDOG=1 only while every port loop advances
// (LoopWatchdog), STOPPING=1 at shutdown. Does nothing when not started by a
// service manager (NOTIFY_SOCKET unset).
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "adapters/daemon/daemon.hpp"

namespace dnbridge::daemon {

// A port as the service manager is told of it.
struct PortSummary {
  std::string name;
  bool started_up = false;  // its start-up checks are over
  std::uint16_t nodes_online = 0;
  std::size_t nodes_configured = 0;
  std::string problem;   // what keeps it off the bus ("interface can7 absent")
  bool stalled = false;  // its loop stopped advancing
};

// The STATUS= line, e.g. "8/9 nodes online (A 8/8, B 0/1: interface can7
// absent)"; "start-up checks: " first while a port has not finished them.
std::string service_status(std::span<const PortSummary> ports);

class ServiceNotifier {
 public:
  ServiceNotifier(const Daemon& daemon, Logger log);
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier&) = delete;
  ServiceNotifier& operator=(const ServiceNotifier&) = delete;

  // After Daemon::start().
  void start();
  // Before Daemon::stop(): no more watchdog feeding, STOPPING=1.
  void stopping();

 private:
  void run();
  void join();

  const Daemon& daemon_;
  Logger log_;
  bool enabled_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace dnbridge::daemon
