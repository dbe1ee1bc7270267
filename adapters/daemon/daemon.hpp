#pragma once
// The bridge of one rack: a DDS participant "dnbridge <rack>", a port loop
// per CAN port, the DDS input thread. start() and stop() are called from one
// thread (main, or a test).
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/dds_input.hpp"
#include "adapters/daemon/dds_publisher.hpp"
#include "adapters/daemon/endpoint_watch.hpp"
#include "adapters/daemon/reload.hpp"
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

// What a reload needs from the program that runs the bridge.
struct ReloadSource {
  // Reads the configuration again (the file the bridge started with);
  // throws ConfigError. Empty: the bridge runs its embedded default.
  std::function<DaemonConfig()> load;
  // Sets the log level a reloaded file has (unless the command line fixed it).
  std::function<void(LogLevel)> set_log_level;
};

class Daemon {
 public:
  // Throws on set-up failures (DDS entities, CAN interfaces, a configuration
  // the master refuses), with a message that says what failed.
  Daemon(DaemonConfig config, LogSink& log, BackendFactory backends, ReloadSource reload = {});
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

  // Reads the configuration again, checks it whole, and applies only what
  // differs (reload.hpp): a file with problems changes nothing. Waits for
  // every port to apply it (at most kReloadWait each). One at a time; any
  // thread but a port's, while running.
  ReloadReport reload();
  static constexpr Duration kReloadWait = seconds(5);
  // From any thread: a reload on the bridge's reload thread. Its report goes
  // to the log and, for a request from DDS (a requester), as a ReloadReply.
  // Every request that arrives while none runs, or while one runs, is
  // answered by the next reload, which reads the file after they came; a
  // reload starts at least kReloadHoldoff after the last one ended, so that
  // requests cannot make the bridge do more. Past kMaxReloadsWaiting
  // requests waiting, answered at once: busy. A request written again
  // (same requester and txid: a client repeats until answered) is one
  // request: while it waits or runs it waits once, and once answered (the
  // last kReloadsRetained, for kReloadRetention) it gets the same report.
  void request_reload(ReloadCall call);
  static constexpr std::size_t kMaxReloadsWaiting = 64;
  static constexpr Duration kReloadHoldoff = seconds(1);
  static constexpr std::size_t kReloadsRetained = 64;
  static constexpr Duration kReloadRetention = seconds(60);

  // The configuration in force (after reloads); not while a reload runs.
  const DaemonConfig& config() const { return config_; }
  port::PortLoop* port(std::string_view name);
  const std::vector<std::unique_ptr<port::PortLoop>>& ports() const { return ports_; }
  // The metrics endpoint ([metrics] listen), when configured.
  const metrics::MetricsServer* metrics_server() const {
    return metrics_server_ ? &*metrics_server_ : nullptr;
  }
  // The process's own counters: its DDS queues, the samples it took, the
  // command hold-offs (the metrics endpoint's process series).
  metrics::ProcessCounters process_counters() const;

 private:
  void run_reloads();
  void log_report(const ReloadReport& report, const std::vector<ReloadCall>& asked_by);

  DaemonConfig config_;
  Logger log_;
  ReloadSource reload_source_;
  std::string host_id_;
  Duration offered_deadline_{};
  std::mutex reload_mutex_;  // one reload at a time; held by reload()
  dds::Participant participant_;
  DdsPublisher publisher_;
  // With [metrics]: the ports publish to DDS and to the metrics both.
  std::shared_ptr<metrics::RackMetrics> metrics_;
  std::optional<port::PublisherTee> tee_;
  std::vector<std::unique_ptr<port::PortLoop>> ports_;
  std::optional<DdsInput> input_;
  std::optional<EndpointWatch> endpoints_;
  // The nodes of every port with a command refresh of `ms`, in words.
  std::string nodes_with_refresh(std::uint32_t ms) const;
  // Last: no scrape reads the publisher or the input once they are gone.
  std::optional<metrics::MetricsServer> metrics_server_;
  bool running_ = false;

  // The reload thread and its queue.
  std::mutex reloads_mutex_;
  std::condition_variable reloads_changed_;
  std::vector<ReloadCall> reloads_;    // what the next reload answers
  std::vector<ReloadCall> reloading_;  // what the one running answers
  struct Answered {
    ReloadCall call;
    std::shared_ptr<const ReloadReport> report;
    std::chrono::steady_clock::time_point at;
  };
  std::deque<Answered> reloaded_;  // newest last
  std::chrono::steady_clock::time_point last_reload_end_{};
  bool reloads_stop_ = false;
  std::thread reload_thread_;
};

}  // namespace dnbridge::daemon
