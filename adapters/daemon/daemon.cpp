#include "adapters/daemon/daemon.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "adapters/daemon/host_identity.hpp"
#include "adapters/socketcan/socketcan_backend.hpp"

namespace dnbridge::daemon {
namespace {

// The deadline the state topics offer: every instance is written at least
// once per its node's maximum publish period (and status period); twice the
// longest leaves room for a loaded machine.
Duration offered_deadline(const DaemonConfig& c) {
  Duration longest = seconds(1);  // the status period
  for (const auto& p : c.ports) {
    for (const auto& n : p.nodes) longest = std::max(longest, n.publish.max_period);
  }
  return 2 * longest;
}

port::PortLoopConfig loop_config(const DaemonConfig& rack, const PortConfig& p,
                                 std::string_view host_id) {
  port::PortLoopConfig c;
  c.port = p.name;
  c.explicit_policy = rack.explicit_policy;
  c.scanner = to_scanner_config(p, host_id);
  c.pumps = to_pump_configs(p);
  for (const auto& n : p.nodes) c.publish.push_back(n.publish);
  return c;
}

}  // namespace

BackendFactory default_backend_factory(LogSink& log) {
  return [&log](const PortConfig& p) -> std::unique_ptr<port::CanBackend> {
    if (p.interface == kSimulatedInterface) {
      throw std::runtime_error(fmt::format(
          "port {}: interface \"{}\" is the simulator's bus, and this program carries no "
          "simulator: dnbridge-sim runs it",
          p.name, p.interface));
    }
    socketcan::SocketCanOptions o;
    o.interface = p.interface;
    o.bitrate = p.bitrate;
    o.bus_off = p.bus_off_recovery;
    try {
      return std::make_unique<socketcan::SocketCanBackend>(
          std::move(o), Logger(log, fmt::format("port {}", p.name)).with("PORT", p.name));
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("port {}: {}", p.name, e.what()));
    }
  };
}

Daemon::Daemon(DaemonConfig config, LogSink& log, BackendFactory backends)
    : config_(std::move(config)),
      log_(log, "dnbridge"),
      participant_(static_cast<dds_domainid_t>(config_.domain_id), config_.rack,
                   config_.security ? security::participant_properties(*config_.security)
                                    : dds::Properties{}),
      publisher_(participant_, config_.rack, offered_deadline(config_), Logger(log, "dds")) {
  // What the explicit gateway lets through beyond Gets is a site decision
  // worth seeing at every start.
  for (std::size_t i = 0; i < rack::kGuardedRequestKinds; ++i) {
    const auto kind = static_cast<rack::GuardedRequest>(i);
    if (config_.explicit_policy.allows(kind)) {
      log_.warn("[explicit_policy] {} = true: remote requesters may send {}; risk: {}",
                rack::policy_key(kind), rack::name_of(kind), rack::risk_of(kind));
    }
  }
  if (config_.metrics_listen) {
    metrics_ =
        std::make_shared<metrics::RackMetrics>(config_.rack, [this] { return process_counters(); });
    // The metrics first: an update in memory, done before the DDS sample
    // that says the same can reach anyone.
    tee_.emplace(*metrics_, publisher_);
  }
  port::PortPublisher& publisher = tee_ ? static_cast<port::PortPublisher&>(*tee_) : publisher_;
  std::map<std::string, port::PortLoop*, std::less<>> by_name;
  const std::string host_id = read_host_id();
  for (const auto& p : config_.ports) {
    const devicenet::ScannerConfig scanner = to_scanner_config(p, host_id);
    log_.info("port {}: master MAC {}, duplicate MAC ID identity vendor {} serial 0x{:08X}{}",
              p.name, scanner.master_mac.value(), scanner.vendor_id, scanner.serial_number,
              p.master_serial_number ? "" : " (derived from this host's identifier)");
    ports_.push_back(std::make_unique<port::PortLoop>(loop_config(config_, p, host_id), backends(p),
                                                      publisher, log));
    by_name[p.name] = ports_.back().get();
  }
  input_.emplace(participant_, publisher_, config_.rack, std::move(by_name),
                 Logger(log, "dds input"));
  if (metrics_) {
    metrics_server_.emplace(*config_.metrics_listen, metrics_);
    const auto listening = metrics_server_->ports();
    log_.info("metrics on http://{}/metrics{}", *config_.metrics_listen,
              listening.empty() ? std::string{} : fmt::format(" (port {})", listening.front()));
  }
}

metrics::ProcessCounters Daemon::process_counters() const {
  metrics::ProcessCounters c;
  for (const auto& [name, q] : {std::pair{"state", publisher_.state_queue()},
                                std::pair{"replies", publisher_.reply_queue()}}) {
    c.queues.push_back({name, q.run, q.replaced, q.refused, q.waiting});
  }
  if (input_) {
    c.commands_taken = input_->commands_taken();
    c.requests_taken = input_->requests_taken();
  }
  return c;
}

Daemon::~Daemon() { stop(); }

port::PortLoop* Daemon::port(std::string_view name) {
  for (auto& p : ports_) {
    if (p->name() == name) return p.get();
  }
  return nullptr;
}

void Daemon::toggle_candump(const std::string& directory) {
  for (auto& p : ports_) {
    const std::string path = fmt::format("{}/dnbridge-{}-candump.log", directory, p->name());
    p->post([path, this](port::CanBackend& backend) {
      auto& log = backend.candump();
      if (log.active()) {
        log.stop();
        log_.info("candump log of {} closed: {}", backend.interface_name(), log.path());
      } else if (auto s = log.start(path, backend.interface_name()); !s) {
        log_.error("candump log {}: {}", path, s.error().message());
      } else {
        log_.info("candump log of {} to {}", backend.interface_name(), path);
      }
    });
  }
}

void Daemon::start() {
  if (running_) return;
  running_ = true;
  log_.info("rack {}: {} port(s) on DDS domain {}", config_.rack, ports_.size(), config_.domain_id);
  for (auto& p : ports_) p->start();
  input_->start();
}

void Daemon::stop() {
  if (!running_) return;
  running_ = false;
  input_->stop();
  for (auto& p : ports_) p->stop();
  for (auto& p : ports_) p->join();
  publisher_.flush(seconds(2));
  log_.info("rack {}: stopped", config_.rack);
}

}  // namespace dnbridge::daemon
