#pragma once
// The bridge of one rack: a DDS participant "dnbridge <rack>", a port loop
// per CAN port, the DDS input thread. start() and stop() are called from one
// thread (main, or a test).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/dds_input.hpp"
#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/metrics/rack_metrics.hpp"
#include "adapters/port/port_loop.hpp"
#include "adapters/port/publisher_tee.hpp"

namespace dnbridge::daemon {

// Makes the CAN backend of a port. default_backend_factory: SocketCAN; it
// refuses interface "simulated" (simulated_backend_factory, in
// dnbridge::daemon_sim, runs it). Throws std::runtime_error for an interface
// it cannot open.
using BackendFactory = std::function<std::unique_ptr<port::CanBackend>(const PortConfig&)>;
BackendFactory default_backend_factory(LogSink& log);

class Daemon {
 public:
  // Throws on set-up failures (DDS entities, CAN interfaces, a configuration
  // the master refuses), with a message that says what failed.
  Daemon(DaemonConfig config, LogSink& log, BackendFactory backends);
  Daemon(DaemonConfig config, LogSink& log)
      : Daemon(std::move(config), log, default_backend_factory(log)) {}
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  void start();
  // Orderly: no more DDS input, every node idle then released, the ports'
  // instances unregistered, the last samples acknowledged (bounded wait).
  void stop();

  // Starts, or stops, a candump -l compatible log of every port's traffic,
  // simulated ones included, one file per port in `directory`
  // (DIR/dnbridge-PORT-candump.log).
  // Any thread; the ports open and close their files on their own threads.
  void toggle_candump(const std::string& directory);

  const DaemonConfig& config() const { return config_; }
  port::PortLoop* port(std::string_view name);
  const std::vector<std::unique_ptr<port::PortLoop>>& ports() const { return ports_; }
  // The metrics endpoint ([metrics] listen), when configured.
  const metrics::MetricsServer* metrics_server() const {
    return metrics_server_ ? &*metrics_server_ : nullptr;
  }

 private:
  metrics::ProcessCounters process_counters() const;

  DaemonConfig config_;
  Logger log_;
  dds::Participant participant_;
  DdsPublisher publisher_;
  // With [metrics]: the ports publish to DDS and to the metrics both.
  std::shared_ptr<metrics::RackMetrics> metrics_;
  std::optional<port::PublisherTee> tee_;
  std::vector<std::unique_ptr<port::PortLoop>> ports_;
  std::optional<DdsInput> input_;
  // Last: no scrape reads the publisher or the input once they are gone.
  std::optional<metrics::MetricsServer> metrics_server_;
  bool running_ = false;
};

}  // namespace dnbridge::daemon
