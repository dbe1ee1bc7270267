#include "adapters/port/port_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "adapters/port/thread_name.hpp"

namespace dnbridge::port {

using devicenet::MacId;

PortLoop::PortLoop(PortLoopConfig config, std::unique_ptr<CanBackend> backend,
                   PortPublisher& publisher, LogSink& log)
    : config_(std::move(config)),
      backend_(std::move(backend)),
      publisher_(publisher),
      log_(Logger(log, fmt::format("port {}", config_.port)).with("PORT", config_.port)),
      publication_(config_.port, config_.status_period, publisher),
      status_(config_.status_period),
      metrics_(config_.status_period),
      scans_(config_.port, publisher) {
  // The master's events reach the rack model first, then this loop.
  port_.emplace(config_.scanner, config_.nodes, backend_->sink(), log_);
  port_->observe(static_cast<devicenet::ScannerObserver&>(*this));
  gateway_.emplace(scanner(), rack::ExplicitGateway::Limits{}, config_.explicit_policy, log_);
  reconfiguration_.emplace(*port_, publication_, metrics_, publisher_, log_);
  reconfiguration_->start(config_);
  note_scan_list();
}

void PortLoop::note_scan_list() {
  std::uint64_t macs = 0;
  std::array<std::uint8_t, MacId::kMax + 1> profile{};
  std::array<std::uint32_t, MacId::kMax + 1> refresh{};
  for (const rack::ProfileNodes* nodes : port_->profiles()) {
    const std::uint8_t p = profile_index(nodes->profile());
    for (std::size_t i = 0; i < nodes->size(); ++i) {
      const rack::NodeView& v = nodes->view(i);
      macs |= std::uint64_t{1} << v.mac.value();
      profile[v.mac.value()] = p;
      refresh[v.mac.value()] = static_cast<std::uint32_t>(
          std::chrono::duration_cast<milliseconds>(v.command_refresh).count());
    }
  }
  for (std::size_t m = 0; m <= MacId::kMax; ++m) {
    profile_of_[m].store(profile[m], std::memory_order_release);
    refresh_ms_[m].store(refresh[m], std::memory_order_relaxed);
  }
  scan_list_.store(macs, std::memory_order_relaxed);
  refresh_generation_.fetch_add(1, std::memory_order_release);
  std::lock_guard lock(command_watch_mutex_);
  if (command_watch_) command_watch_();
}

std::uint8_t PortLoop::profile_index(std::string_view name) {
  for (std::size_t p = 0; p < profile_count_; ++p) {
    if (profile_names_[p] == name) return static_cast<std::uint8_t>(p + 1);
  }
  if (profile_count_ == kMaxProfiles) {
    throw std::logic_error(fmt::format("more than {} node profiles on one port", kMaxProfiles));
  }
  profile_names_[profile_count_] = name;
  return static_cast<std::uint8_t>(++profile_count_);
}

void PortLoop::watch_command_state(std::function<void()> watch) {
  std::lock_guard lock(command_watch_mutex_);
  command_watch_ = std::move(watch);
}

void PortLoop::expire_silent_commanders(TimePoint now) {
  bool any = false;
  for (rack::ProfileNodes* nodes : port_->profiles()) {
    for (const auto& s : nodes->expire_silent_commanders(now)) {
      any = true;
      silences_[s.mac.value()].fetch_add(1, std::memory_order_release);
      silent_log_.warn(
          log_, now, "node {}: commander {} silent for {} ms (command_refresh_ms): {}",
          s.mac.value(), s.issuer, std::chrono::duration_cast<milliseconds>(s.silent_for).count(),
          s.outputs_held ? "outputs held (no_commander = \"hold\")" : "no live commander left");
    }
  }
  if (!any) return;
  std::lock_guard lock(command_watch_mutex_);
  if (command_watch_) command_watch_();
}

PortLoop::~PortLoop() {
  if (thread_.joinable()) {
    stop();
    join();
  }
}

void PortLoop::start() {
  running_ = true;
  thread_ = std::thread([this] { run(); });
  name_thread(thread_, "port " + config_.port);
}

void PortLoop::stop() { push(Stop{}); }

void PortLoop::join() {
  if (thread_.joinable()) thread_.join();
}

std::string PortLoop::problem() const {
  std::lock_guard lock(problem_mutex_);
  return problem_;
}

void PortLoop::command(MacId mac, rack::NodeCommand command, std::string issuer) {
  push(Command{mac, profile_of(mac), std::move(command), std::move(issuer)});
}
void PortLoop::release_command(MacId mac) { push(Release{mac, profile_of(mac)}); }
void PortLoop::explicit_request(rack::ExplicitCall call) {
  std::optional<rack::ExplicitCall> refused;
  {
    std::lock_guard lock(inbox_mutex_);
    if (calls_.size() < kMaxQueuedCalls) {
      calls_.push_back(std::move(call));
    } else {
      refused = std::move(call);
    }
  }
  if (!refused) {
    backend_->wake();
    return;
  }
  calls_refused_.fetch_add(1, std::memory_order_relaxed);
  publisher_.explicit_reply(config_.port,
                            rack::refuse(*refused, rack::TransactionStatus::kOutOfBuffers,
                                         fmt::format("{} requests already wait for port {}",
                                                     kMaxQueuedCalls, config_.port)));
}
void PortLoop::post(std::function<void(CanBackend&)> fn) { push(std::move(fn)); }
void PortLoop::scan_request(ScanCall call) { push(std::move(call)); }

std::future<PortChange> PortLoop::reconfigure(PortLoopConfig next) {
  Reconfigure r{std::make_shared<PortLoopConfig>(std::move(next)),
                std::make_shared<std::promise<PortChange>>()};
  auto done = r.done->get_future();
  push(std::move(r));
  return done;
}

void PortLoop::apply(const Reconfigure& r, TimePoint now) {
  PortChange change = reconfiguration_->apply(config_, *r.config, *gateway_, now);
  if (change.refused.empty()) {
    note_scan_list();
    status_.changed(now);
  }
  r.done->set_value(std::move(change));
}

void PortLoop::handle_scan_call(const ScanCall& call, TimePoint now) {
  if (!scans_.request(call, scanner().scanning_bus(), bus_seen_, now)) return;
  if (auto started = scanner().scan_bus(now); !started) {
    scans_.start_refused(
        fmt::format("{}: {}", devicenet::to_string(scanner().state()), scanner().reason()));
  }
}

void PortLoop::push(Item item) {
  {
    std::lock_guard lock(inbox_mutex_);
    inbox_.push_back(std::move(item));
  }
  backend_->wake();
}

bool PortLoop::drain_inbox(TimePoint now) {
  std::vector<Item> items;
  std::vector<rack::ExplicitCall> calls;
  {
    std::lock_guard lock(inbox_mutex_);
    items.swap(inbox_);
    const std::size_t n = std::min(calls_.size(), kCallsPerPass);
    calls.assign(std::make_move_iterator(calls_.begin()),
                 std::make_move_iterator(calls_.begin() + static_cast<std::ptrdiff_t>(n)));
    calls_.erase(calls_.begin(), calls_.begin() + static_cast<std::ptrdiff_t>(n));
    calls_waiting_ = !calls_.empty();
  }
  bool keep_running = true;
  for (auto& item : items) {
    if (auto* c = std::get_if<Command>(&item)) {
      // The MAC was checked against the scan list where the command came
      // in (profile_of); a reload may have changed it since.
      rack::ProfileNodes* nodes = port_->nodes_of(c->mac);
      if (!nodes || nodes->profile() != c->profile) {
        log_.warn("command refused: from {}: MAC {} is {}", c->issuer, c->mac.value(),
                  c->profile.empty()
                      ? std::string("not in this port's scan list")
                      : fmt::format("no longer a node of profile \"{}\" (a reload)", c->profile));
      } else if (auto s = nodes->command(c->mac, c->command, c->issuer, now); !s) {
        log_.warn("command refused: {}", nodes->node(c->mac)->last_command_refused);
      }
    } else if (auto* r = std::get_if<Release>(&item)) {
      // A release for a node of another profile (a reload came between)
      // is not this node's.
      rack::ProfileNodes* nodes = port_->nodes_of(r->mac);
      if (nodes && nodes->profile() == r->profile && nodes->release_command(r->mac, now)) {
        log_.info("node {}: no live commander left", r->mac.value());
      }
    } else if (auto* scan = std::get_if<ScanCall>(&item)) {
      handle_scan_call(*scan, now);
    } else if (auto* re = std::get_if<Reconfigure>(&item)) {
      if (keep_running) {
        apply(*re, now);
      } else {
        PortChange refused;
        refused.refused = "the port is stopping";
        re->done->set_value(std::move(refused));
      }
    } else if (auto* fn = std::get_if<std::function<void(CanBackend&)>>(&item)) {
      (*fn)(*backend_);
    } else {
      keep_running = false;
    }
  }
  for (const auto& call : calls) {
    if (auto answer = gateway_->on_request(call, now))
      publisher_.explicit_reply(config_.port, *answer);
  }
  gateway_->expire(now);
  return keep_running;
}

void PortLoop::run() {
  TimePoint now = backend_->now();
  publication_.start(now);
  metrics_.start(now);
  status_.start(now);
  bool stopping = false;
  TimePoint stop_deadline = kNever;
  for (;;) {
    const auto pass_start = std::chrono::steady_clock::now();
    heartbeat_.fetch_add(1, std::memory_order_relaxed);
    now = backend_->now();
    // (A master that starts now checks its MAC anyway: no re-check for it.)
    const bool master_was_started = master_started_;
    if (!stopping) start_master_when_up(now);
    while (scanner().next_deadline() <= now) scanner().on_timer(now);
    const bool keep_running = drain_inbox(now);
    // After the inbox: a command that came while the loop waited renews its
    // node's refresh before the refresh is looked at.
    expire_silent_commanders(now);
    if (!keep_running && !stopping) {
      stopping = true;
      stop_deadline = now + config_.shutdown_timeout;
      log_.info("stopping: idling and releasing every node");
      scanner().stop(now);
    }
    follow_bus(backend_->counters(), master_was_started, stopping, now);
    publish(now, false);
    // Requests still queued are handled first: each gets its one reply.
    if (stopping && !calls_waiting_ && (scanner().stopped() || now >= stop_deadline)) break;
    const TimePoint wake = calls_waiting_ ? now : next_wake(stop_deadline);
    note_busy(pass_start);
    FrameReceiver& receiver = *this;
    backend_->wait(wake, receiver);
  }
  if (!scanner().stopped()) log_.warn("stopped before every node was released");
  publish(backend_->now(), true);
  publisher_.port_stopped(config_.port);
  running_ = false;
}

void PortLoop::follow_bus(const BusCounters& counters, bool master_was_started, bool stopping,
                          TimePoint now) {
  const BusState bus = counters.state;
  // A bus that comes back (bus-off recovered, the interface up again):
  // the master checks its own MAC again before it scans, and every node
  // comes back idle. A loss that began and ended while the loop was not
  // looking (both within one wait) counts as much as one it saw.
  const bool unseen_loss =
      counters.losses != bus_losses_seen_ && !bus_lost(bus_seen_) && !bus_lost(bus);
  bus_losses_seen_ = counters.losses;
  if (bus != bus_seen_ || unseen_loss) {
    if ((unseen_loss || (bus_lost(bus_seen_) && !bus_lost(bus))) && master_was_started &&
        !stopping) {
      scanner().recheck_mac(unseen_loss                    ? "the bus was lost and is back"
                            : bus_seen_ == BusState::kDown ? "the interface is up again"
                                                           : "bus-off recovered",
                            now);
    }
    bus_seen_ = bus;
  }
  // A change of the bus or interface state is published at once.
  if (bus != bus_state_) status_.changed(now);
}

TimePoint PortLoop::next_wake(TimePoint stop_deadline) const {
  // BusMetrics measures only as a PortStatus is made (bus_metrics.hpp), a
  // bus scan's steps are the master's timers and a reload is applied as it
  // comes: none has a time of its own here.
  TimePoint wake = std::min({port_->scanner().next_deadline(), stop_deadline,
                             gateway_->next_expiry(), status_.next_due(), publication_.next_due()});
  for (const rack::ProfileNodes* nodes : port_->profiles()) {
    wake = std::min(wake, nodes->next_refresh_deadline());
  }
  return wake;
}

void PortLoop::start_master_when_up(TimePoint now) {
  if (master_started_) return;
  if (backend_->counters().state != BusState::kDown) {
    master_started_ = true;
    scanner().start(now);
    return;
  }
  if (!started_up_.load(std::memory_order_relaxed)) {
    // Start-up checks end here for this port; the other ports need not
    // wait for an interface that may never come.
    log_.warn(
        "{}: the master starts (duplicate MAC ID check, then scanning) when the interface is up",
        backend_->problem());
    started_up_.store(true, std::memory_order_relaxed);
  }
}

void PortLoop::publish(TimePoint now, bool force) {
  publication_.publish(*port_, now, force);
  if (status_.due(now, force)) publish_port(now);
}

void PortLoop::publish_port(TimePoint now) {
  PortStatusView s;
  s.port = config_.port;
  s.interface_name = backend_->interface_name();
  s.bitrate = backend_->bitrate();
  s.master_mac = config_.scanner.master_mac;
  s.state = scanner().state();
  s.reason = scanner().reason();
  s.bus = backend_->counters();
  bus_state_ = s.bus.state;
  // The interface's trouble first: the master's own state means little
  // while nothing reaches the bus.
  if (!master_started_) s.reason = "waiting for the interface to start the MAC check";
  const std::string problem = backend_->problem();
  if (!problem.empty()) {
    s.reason = s.reason.empty() ? problem : fmt::format("{} ({})", problem, s.reason);
  }
  {
    std::lock_guard lock(problem_mutex_);
    if (problem != problem_) problem_ = problem;
  }
  for (const rack::ProfileNodes* nodes : port_->profiles()) {
    for (std::size_t i = 0; i < nodes->size(); ++i) {
      ++s.nodes_configured;
      if (nodes->view(i).online) ++s.nodes_online;
    }
  }
  // Rates are measured over whole status periods; a state change in between
  // publishes the last measured ones.
  metrics_.measure_if_due(s.bus, s.bitrate, node_polls(), now);
  const BusMetrics::Figures& figures = metrics_.figures();
  s.frames_per_second = figures.frames_per_second;
  s.bus_load_percent = figures.bus_load_percent;
  s.scan_cycle_ms = figures.scan_cycle_ms;
  {
    std::lock_guard lock(inbox_mutex_);
    s.explicit_outstanding = static_cast<std::uint32_t>(calls_.size());
  }
  s.explicit_outstanding += static_cast<std::uint32_t>(gateway_->in_progress());
  s.explicit_retained = static_cast<std::uint32_t>(gateway_->retained());
  s.explicit_refused_for_limits =
      gateway_->refused_for_limits() + calls_refused_.load(std::memory_order_relaxed);
  s.loop_longest_pass_ms = std::chrono::duration<double, std::milli>(longest_pass_).count();
  const auto heard = scanner().unconfigured_heard(backend_->now());
  for (std::size_t mac = 0; mac < heard.size(); ++mac) {
    if (heard.test(mac)) s.unconfigured_macs.push_back(static_cast<std::uint8_t>(mac));
  }
  longest_pass_ = Duration::zero();
  nodes_online_.store(s.nodes_online, std::memory_order_relaxed);
  publisher_.port_status(s, status_.source_time(now));
  status_.published(now);
}

std::vector<BusMetrics::NodePolls> PortLoop::node_polls() const {
  std::vector<BusMetrics::NodePolls> polls;
  for (const rack::ProfileNodes* nodes : port_->profiles()) {
    for (std::size_t i = 0; i < nodes->size(); ++i) {
      const MacId mac = nodes->view(i).mac;
      const auto* node = port_->scanner().node(mac);
      polls.push_back(
          {mac, node->state() == devicenet::NodeState::kOnline, node->counters().polls});
    }
  }
  return polls;
}

void PortLoop::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  const auto start = std::chrono::steady_clock::now();
  scanner().on_frame(frame, rx_time);
  note_busy(start);
}

void PortLoop::note_busy(std::chrono::steady_clock::time_point since) {
  longest_pass_ = std::max<Duration>(longest_pass_, std::chrono::duration_cast<Duration>(
                                                        std::chrono::steady_clock::now() - since));
}

void PortLoop::on_port_state(devicenet::PortState s, const std::string&, TimePoint at) {
  if (s == devicenet::PortState::kRunning || s == devicenet::PortState::kDuplicateMac) {
    started_up_.store(true, std::memory_order_relaxed);
  }
  status_.changed(at);
}
void PortLoop::on_node_state(MacId m, devicenet::NodeState f, devicenet::NodeState t,
                             const std::string& r, TimePoint) {
  if (t == devicenet::NodeState::kOnline || f == devicenet::NodeState::kOnline) {
    const std::string mac = std::to_string(m.value());
    log_.with("MAC", mac)
        .with("NODE", mac)
        .with("NODE_STATE", std::string(devicenet::to_string(t)))
        .info("node {} {} -> {}: {}", m.value(), devicenet::to_string(f), devicenet::to_string(t),
              r);
  }
  status_.changed();
}
void PortLoop::on_explicit_result(std::uint32_t id, MacId, const devicenet::ExplicitResult& r,
                                  TimePoint at) {
  if (auto answer = gateway_->on_result(id, r, at))
    publisher_.explicit_reply(config_.port, *answer);
}

}  // namespace dnbridge::port
