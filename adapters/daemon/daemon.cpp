#include "adapters/daemon/daemon.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "adapters/daemon/host_identity.hpp"
#include "adapters/port/thread_name.hpp"
#include "adapters/socketcan/socketcan_backend.hpp"
#include "adapters/version/version.hpp"

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
  c.nodes = to_port_nodes(p);
  for (const auto& n : p.nodes) c.publish[n.pump.node.mac] = n.publish;
  return c;
}

// What the explicit gateway lets through beyond Gets is a site decision
// worth seeing at every start and reload.
void warn_of_policy(Logger& log, const rack::ExplicitPolicy& policy) {
  for (std::size_t i = 0; i < rack::kGuardedRequestKinds; ++i) {
    const auto kind = static_cast<rack::GuardedRequest>(i);
    if (policy.allows(kind)) {
      log.warn("[explicit_policy] {} = true: remote requesters may send {}; risk: {}",
               rack::policy_key(kind), rack::name_of(kind), rack::risk_of(kind));
    }
  }
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

Daemon::Daemon(DaemonConfig config, LogSink& log, BackendFactory backends, ReloadSource reload)
    : config_(std::move(config)),
      log_(log, "dnbridge"),
      reload_source_(std::move(reload)),
      host_id_(read_host_id()),
      offered_deadline_(offered_deadline(config_)),
      participant_(static_cast<dds_domainid_t>(config_.domain_id), config_.rack,
                   config_.security ? security::participant_properties(*config_.security)
                                    : dds::Properties{},
                   dds::host_user_data(version::number())),
      publisher_(participant_, config_.rack, offered_deadline_, Logger(log, "dds")) {
  warn_of_policy(log_, config_.explicit_policy);
  if (config_.metrics_listen) {
    metrics_ =
        std::make_shared<metrics::RackMetrics>(config_.rack, [this] { return process_counters(); });
    // The metrics first: an update in memory, done before the DDS sample
    // that says the same can reach anyone.
    tee_.emplace(*metrics_, publisher_);
  }
  port::PortPublisher& publisher = tee_ ? static_cast<port::PortPublisher&>(*tee_) : publisher_;
  std::map<std::string, port::PortLoop*, std::less<>> by_name;
  for (const auto& p : config_.ports) {
    const devicenet::ScannerConfig scanner = to_scanner_config(p, host_id_);
    log_.info("port {}: master MAC {}, duplicate MAC ID identity vendor {} serial 0x{:08X}{}",
              p.name, scanner.master_mac.value(), scanner.vendor_id, scanner.serial_number,
              p.master_serial_number ? "" : " (derived from this host's identifier)");
    ports_.push_back(std::make_unique<port::PortLoop>(loop_config(config_, p, host_id_),
                                                      backends(p), publisher, log));
    by_name[p.name] = ports_.back().get();
  }
  input_.emplace(
      participant_, publisher_, config_.rack, std::move(by_name), Logger(log, "dds input"),
      [this](ReloadCall call) { request_reload(call); }, config_.max_commander_lease);
  publisher_.set_max_commander_lease(config_.max_commander_lease);
  EndpointWatch::Settings watch;
  watch.rack = config_.rack;
  watch.max_commander_lease = config_.max_commander_lease;
  watch.nodes_with_refresh = [this](std::uint32_t ms) { return nodes_with_refresh(ms); };
  watch.counted = [this](std::uint32_t refused, std::uint32_t unmatched) {
    publisher_.set_endpoint_counts(refused, unmatched);
  };
  endpoints_.emplace(participant_, std::move(watch), Logger(log, "dds endpoints"));
  if (metrics_) {
    metrics_server_.emplace(*config_.metrics_listen, metrics_);
    const auto listening = metrics_server_->ports();
    log_.info("metrics on http://{}/metrics{}", *config_.metrics_listen,
              listening.empty() ? std::string{} : fmt::format(" (port {})", listening.front()));
  }
}

metrics::ProcessCounters Daemon::process_counters() const {
  metrics::ProcessCounters c;
  // State samples are written on the ports' threads: replies alone queue.
  const auto replies = publisher_.reply_queue();
  c.queues.push_back({"replies", replies.run, replies.refused, replies.waiting});
  c.state_write_failures = publisher_.state_write_failures();
  if (input_) {
    c.commands_taken = input_->commands_taken();
    c.requests_taken = input_->requests_taken();
    c.command_holdoffs = input_->command_holdoffs();
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
  reloads_stop_ = false;
  reload_thread_ = std::thread([this] { run_reloads(); });
  port::name_thread(reload_thread_, "reload");
  input_->start();
  endpoints_->start();
}

std::string Daemon::nodes_with_refresh(std::uint32_t ms) const {
  std::string out;
  for (const auto& p : ports_) {
    std::string macs;
    for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
      const auto mac = *devicenet::MacId::from(m);
      if (p->has_node(mac) && p->command_refresh_ms(mac) == ms) {
        macs += fmt::format("{}{}", macs.empty() ? "" : ", ", m);
      }
    }
    if (!macs.empty())
      out += fmt::format("{}port {}: {}", out.empty() ? "" : "; ", p->name(), macs);
  }
  return out;
}

void Daemon::stop() {
  if (!running_) return;
  running_ = false;
  endpoints_->stop();
  input_->stop();
  {
    std::lock_guard lock(reloads_mutex_);
    reloads_stop_ = true;
  }
  reloads_changed_.notify_all();
  if (reload_thread_.joinable()) reload_thread_.join();
  for (auto& p : ports_) p->stop();
  for (auto& p : ports_) p->join();
  publisher_.flush(seconds(2));
  log_.info("rack {}: stopped", config_.rack);
}

void Daemon::request_reload(ReloadCall call) {
  {
    std::lock_guard lock(reloads_mutex_);
    const auto same = [&](const ReloadCall& r) {
      return r.requester == call.requester && r.txid == call.txid;
    };
    // A SIGHUP (no requester) while one waits is that one.
    if (std::any_of(reloads_.begin(), reloads_.end(), same)) return;
    if (!call.requester.empty()) {
      if (std::any_of(reloading_.begin(), reloading_.end(), same)) return;
      const auto now = std::chrono::steady_clock::now();
      while (!reloaded_.empty() && now - reloaded_.front().at > kReloadRetention) {
        reloaded_.pop_front();
      }
      for (const auto& a : reloaded_) {
        if (same(a.call)) {
          publisher_.reload_reply(call, *a.report);
          return;
        }
      }
    }
    if (reloads_.size() < kMaxReloadsWaiting || call.requester.empty()) {
      reloads_.push_back(std::move(call));
      reloads_changed_.notify_all();
      return;
    }
  }
  ReloadReport busy;
  busy.status = ReloadStatus::kBusy;
  busy.message = fmt::format("{} reload requests already wait: ask again once they are answered",
                             kMaxReloadsWaiting);
  publisher_.reload_reply(call, busy);
}

void Daemon::run_reloads() {
  for (;;) {
    {
      std::unique_lock lock(reloads_mutex_);
      reloads_changed_.wait(lock, [&] { return reloads_stop_ || !reloads_.empty(); });
      reloads_changed_.wait_until(lock, last_reload_end_ + kReloadHoldoff,
                                  [&] { return reloads_stop_; });
      if (reloads_stop_) return;
      reloading_.swap(reloads_);
    }
    const auto report = std::make_shared<const ReloadReport>(reload());
    log_report(*report, reloading_);
    std::lock_guard lock(reloads_mutex_);
    const auto now = std::chrono::steady_clock::now();
    last_reload_end_ = now;
    for (auto& call : reloading_) {
      if (call.requester.empty()) continue;
      publisher_.reload_reply(call, *report);
      reloaded_.push_back({std::move(call), report, now});
      if (reloaded_.size() > kReloadsRetained) reloaded_.pop_front();
    }
    reloading_.clear();
  }
}

void Daemon::log_report(const ReloadReport& r, const std::vector<ReloadCall>& asked_by) {
  std::string origin;
  std::size_t requests = 0;
  for (const auto& call : asked_by) {
    if (call.requester.empty()) {
      origin = "SIGHUP";
    } else if (requests++ == 0) {
      origin +=
          fmt::format("{}{} (txid {})", origin.empty() ? "" : ", ", call.requester, call.txid);
    }
  }
  if (requests > 1) origin += fmt::format(" and {} other request(s)", requests - 1);
  const std::string head = fmt::format("reload asked by {}: {}", origin, r.message);
  if (r.status == ReloadStatus::kApplied) {
    log_.info("{}", head);
  } else {
    log_.error("{}", head);
  }
  for (const auto& line : r.applied) log_.info("reload: {}", line);
  for (const auto& line : r.needs_restart) log_.warn("reload: needs a restart: {}", line);
  for (const auto& line : r.problems) log_.error("reload: {}", line);
}

ReloadReport Daemon::reload() {
  std::lock_guard lock(reload_mutex_);
  ReloadReport r;
  if (!reload_source_.load) {
    r.status = ReloadStatus::kNoFile;
    r.message = "the bridge runs its embedded default: there is no file to read again";
    return r;
  }
  DaemonConfig next;
  try {
    next = reload_source_.load();
  } catch (const ConfigError& e) {
    r.status = ReloadStatus::kRefused;
    r.problems = e.problems();
  } catch (const std::exception& e) {
    r.status = ReloadStatus::kRefused;
    r.problems = {e.what()};
  }
  r.file = r.status == ReloadStatus::kRefused ? config_.source : next.source;
  ReloadPlan plan;
  std::vector<port::PortLoopConfig> loops;
  if (r.status != ReloadStatus::kRefused) {
    plan = plan_reload(config_, next, offered_deadline_);
    // Every port's scan list as its master takes it, before any is applied.
    for (const auto& p : plan.in_force.ports) {
      try {
        loops.push_back(loop_config(plan.in_force, p, host_id_));
        const auto& loop = loops.back();
        devicenet::Scanner::check(rack::RackPort::scan_list(loop.scanner, loop.nodes));
      } catch (const std::exception& e) {
        r.status = ReloadStatus::kRefused;
        r.problems.push_back(fmt::format("port {}: {}", p.name, e.what()));
      }
    }
  }
  if (r.status == ReloadStatus::kRefused) {
    r.message = fmt::format("{}: {} problem(s): nothing changed", r.file, r.problems.size());
    return r;
  }
  // The command readers of every command refresh the file gives exist
  // before a port applies it: a node's commands never go unread meanwhile.
  std::vector<std::uint32_t> refreshes;
  for (const auto& c : loops) {
    for (const auto& list : c.nodes.lists()) {
      for (std::size_t i = 0; i < list->size(); ++i) {
        refreshes.push_back(static_cast<std::uint32_t>(
            std::chrono::duration_cast<milliseconds>(list->command_refresh(i)).count()));
      }
    }
  }
  if (input_) input_->prepare_command_refreshes(refreshes);
  std::vector<std::pair<std::string, std::future<port::PortChange>>> pending;
  for (auto& c : loops) {
    port::PortLoop* loop = port(c.port);
    if (!loop) continue;
    std::string name = c.port;
    auto done = loop->reconfigure(std::move(c));
    pending.emplace_back(std::move(name), std::move(done));
  }
  bool policy_changed = false;
  for (auto& [name, done] : pending) {
    if (done.wait_for(kReloadWait) != std::future_status::ready) {
      r.problems.push_back(fmt::format(
          "port {}: did not confirm the change within {} s (it applies it at its next pass)", name,
          std::chrono::duration_cast<std::chrono::seconds>(kReloadWait).count()));
      continue;
    }
    const port::PortChange change = done.get();
    if (!change.refused.empty()) {
      r.problems.push_back(fmt::format("port {}: not applied: {}", name, change.refused));
      continue;
    }
    policy_changed = policy_changed || change.explicit_policy_changed;
    for (auto& line : describe(name, change)) r.applied.push_back(std::move(line));
  }
  if (plan.in_force.log_level != config_.log_level) {
    if (reload_source_.set_log_level) reload_source_.set_log_level(plan.in_force.log_level);
    r.applied.push_back(fmt::format("log_level {} (was {})", to_string(plan.in_force.log_level),
                                    to_string(config_.log_level)));
  }
  if (policy_changed) warn_of_policy(log_, plan.in_force.explicit_policy);
  for (const auto& w : plan.in_force.warnings) log_.warn("{}", w);
  r.needs_restart = std::move(plan.needs_restart);
  config_ = std::move(plan.in_force);
  r.status = r.problems.empty() ? ReloadStatus::kApplied : ReloadStatus::kIncomplete;
  if (!r.problems.empty()) {
    r.message = fmt::format("{}: checked; not every port applied it", r.file);
  } else if (r.applied.empty()) {
    r.message = fmt::format("{}: nothing differs from the configuration in force{}", r.file,
                            r.needs_restart.empty() ? "" : " that can change without a restart");
  } else {
    r.message = fmt::format("{}: applied ({} change(s){})", r.file, r.applied.size(),
                            r.needs_restart.empty() ? std::string()
                                                    : fmt::format("; {} setting(s) need a restart",
                                                                  r.needs_restart.size()));
  }
  return r;
}

}  // namespace dnbridge::daemon
