#pragma once
// The daemon's side of systemd's notify protocol (sd_notify(3)), for
// dnbridge@.service (Type=notify, WatchdogSec=): READY=1 once every port has
// finished its start-up checks, STATUS= with the nodes online, WATCHDOG=1
// only while every port loop is alive, STOPPING=1 at shutdown. Does nothing
// when not started by a service manager (NOTIFY_SOCKET unset).
#include <condition_variable>
#include <mutex>
#include <thread>

#include "adapters/daemon/daemon.hpp"

namespace dnbridge::daemon {

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

  const Daemon& daemon_;
  Logger log_;
  bool enabled_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace dnbridge::daemon
