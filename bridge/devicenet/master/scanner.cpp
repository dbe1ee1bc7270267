#include "bridge/devicenet/master/scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <tuple>

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

DuplicateMacCheck::Config mac_check_config(const ScannerConfig& c) {
  DuplicateMacCheck::Config m;
  m.window = c.duplicate_mac_window;
  m.vendor_id = c.vendor_id;
  m.serial_number = c.serial_number;
  return m;
}

// One node's own settings, and its MAC against the master's.
void validate_node(const ScannerConfig& c, const NodeConfig& n) {
  const unsigned mac = n.mac.value();
  if (mac > MacId::kMax) throw std::invalid_argument(fmt::format("node MAC {} out of range", mac));
  if (n.mac == c.master_mac) {
    throw std::invalid_argument(fmt::format("node {} has the master's MAC", mac));
  }
  if (n.poll_period <= Duration::zero()) {
    throw std::invalid_argument(fmt::format("node {}: poll period must be positive", mac));
  }
  if (n.immediate_poll_min_gap < Duration::zero()) {
    throw std::invalid_argument(
        fmt::format("node {}: immediate poll minimum gap must not be negative", mac));
  }
  if (n.expected_packet_rate < n.poll_period) {
    throw std::invalid_argument(
        fmt::format("node {}: expected packet rate shorter than the poll period", mac));
  }
  if (n.profile.consumed_size > Node::kMaxIoSize || n.profile.produced_size > Node::kMaxIoSize) {
    throw std::invalid_argument(
        fmt::format("node {}: poll messages over {} bytes", mac, Node::kMaxIoSize));
  }
  if (const auto& in = n.profile.input_connection) {
    if (!in->strobed() && in->expected_packet_rate <= Duration::zero()) {
      throw std::invalid_argument(fmt::format("node {}: {} expected packet rate must be positive",
                                              mac, to_string(in->kind)));
    }
    const std::size_t most = in->strobed() ? kMaxStrobeResponse : Node::kMaxIoSize;
    if (in->produced_size > most) {
      throw std::invalid_argument(
          fmt::format("node {}: {} messages over {} bytes", mac, to_string(in->kind), most));
    }
  }
}

}  // namespace

void Scanner::check(const ScannerConfig& c) {
  std::array<bool, MacId::kMax + 1> seen{};
  for (const auto& n : c.nodes) {
    validate_node(c, n);
    if (seen[n.mac.value()]) {
      throw std::invalid_argument(fmt::format("MAC {} is in the scan list twice", n.mac.value()));
    }
    seen[n.mac.value()] = true;
  }
}

std::string_view to_string(InputKind kind) noexcept {
  switch (kind) {
    case InputKind::kChangeOfState:
      return "change-of-state";
    case InputKind::kCyclic:
      return "cyclic";
    case InputKind::kBitStrobe:
      return "bit-strobe";
  }
  return "?";
}

std::string_view to_string(PortState state) noexcept {
  switch (state) {
    case PortState::kStopped:
      return "stopped";
    case PortState::kCheckingMac:
      return "checking MAC";
    case PortState::kRunning:
      return "running";
    case PortState::kStopping:
      return "stopping";
    case PortState::kDuplicateMac:
      return "duplicate MAC";
  }
  return "?";
}

Scanner::Scanner(ScannerConfig config, can::FrameSink& sink, ScannerObserver& observer, Logger log)
    : config_(std::move(config)),
      sink_(sink),
      observer_(observer),
      log_(std::move(log)),
      mac_check_(config_.master_mac, mac_check_config(config_)) {
  check(config_);
  unconfigured_last_heard_.fill(kNever);
  stray_strobe_release_.fill(kNever);
  nodes_.reserve(config_.nodes.size());
  for (const auto& n : config_.nodes) make_node(n);
}

Node& Scanner::make_node(NodeConfig config) {
  // Every line of a node carries its MAC ID, as MAC and NODE.
  const std::string mac = std::to_string(config.mac.value());
  Logger node_log = log_.named(fmt::format("{} node {}", log_.component(), mac))
                        .with("MAC", mac)
                        .with("NODE", mac);
  const std::uint8_t at = config.mac.value();
  nodes_.push_back(
      std::make_unique<Node>(std::move(config), config_, sink_, observer_, std::move(node_log)));
  by_mac_[at] = nodes_.back().get();
  return *nodes_.back();
}

namespace {

// The port's timings (Scanner::same_timings), one list for comparing and
// for copying them.
template <class Config>
auto timings(Config& c) {
  return std::tie(c.explicit_messaging.response_timeout, c.allocate_retry_min, c.allocate_retry_max,
                  c.fault_recheck, c.max_consecutive_errors, c.poll_response_timeout,
                  c.poll_batch_window, c.scan_response_timeout);
}

}  // namespace

bool Scanner::same_timings(const ScannerConfig& a, const ScannerConfig& b) {
  return timings(a) == timings(b);
}

void Scanner::retune(const ScannerConfig& next) {
  if (same_timings(config_, next)) return;
  timings(config_) = timings(next);
  for (auto& n : nodes_) n->apply_port_timings();
  for (auto& n : leaving_) n->apply_port_timings();
  log_.info("port timings changed: in force for every node");
}

Status Scanner::add_node(NodeConfig node, TimePoint now) {
  if (state_ == PortState::kStopping) return Errc::kStopped;
  validate_node(config_, node);
  const MacId mac = node.mac;
  if (find(mac)) {
    throw std::invalid_argument(fmt::format("MAC {} is in the scan list twice", mac.value()));
  }
  end_bus_scan("the scan list changed", now);
  // Heard before as a node the configuration did not have: now it has it.
  unconfigured_last_heard_[mac.value()] = kNever;
  answering_other_master_.reset(mac.value());
  Node& n = make_node(std::move(node));
  const bool waits = leaving(mac);
  log_.info("node {} added to the scan list{}", mac.value(),
            waits ? ": it starts once its MAC's previous node is released" : "");
  if (state_ == PortState::kDuplicateMac) {
    n.halt("port stopped: duplicate master MAC", now);
  } else if (state_ == PortState::kRunning && !waits) {
    n.set_poll_phase(now);
    n.start(now, now);
  }
  if (state_ == PortState::kRunning) schedule_strobes(now);
  // Otherwise the node starts when the port scans (begin_scanning) or when
  // the one leaving is released (reap).
  return {};
}

Status Scanner::remove_node(MacId mac, TimePoint now) {
  if (state_ == PortState::kStopping) return Errc::kStopped;
  Node* n = find(mac);
  if (!n) return Errc::kOutOfRange;
  end_bus_scan("the scan list changed", now);
  by_mac_[mac.value()] = nullptr;
  auto it = std::find_if(nodes_.begin(), nodes_.end(), [&](const auto& p) { return p.get() == n; });
  std::unique_ptr<Node> node = std::move(*it);
  nodes_.erase(it);
  if (state_ != PortState::kRunning || !node->started()) {
    // No connection to give back: the node was never started (a node put
    // back while its MAC's previous one is released), or its connections
    // went with the bus or the master's MAC.
    log_.info("node {} taken out of the scan list", mac.value());
    return {};
  }
  log_.info("node {} taken out of the scan list: idle, then released", mac.value());
  node->retire("taking it out of the scan list", now);
  leaving_.push_back(std::move(node));
  reap(now);
  schedule_strobes(now);
  return {};
}

void Scanner::reap(TimePoint now) {
  for (auto it = leaving_.begin(); it != leaving_.end();) {
    if (!(*it)->stopped()) {
      ++it;
      continue;
    }
    const MacId mac = (*it)->mac();
    it = leaving_.erase(it);
    log_.info("node {} released: out of the scan list", mac.value());
    Node* next = find(mac);
    if (next && state_ == PortState::kRunning) {
      next->set_poll_phase(now);
      next->start(now, now);
    } else if (next && state_ == PortState::kStopping) {
      next->begin_shutdown(now);
    }
  }
}

void Scanner::drop_leaving(std::string_view reason, TimePoint now) {
  for (auto& n : leaving_) n->halt(reason, now);
  leaving_.clear();
}

bool Scanner::leaving(MacId mac) const {
  return std::any_of(leaving_.begin(), leaving_.end(),
                     [&](const auto& n) { return n->mac() == mac; });
}

Node* Scanner::route(MacId mac) {
  for (auto& n : leaving_) {
    if (n->mac() == mac) return n.get();
  }
  return find(mac);
}

void Scanner::set_state(PortState next, std::string reason, TimePoint now) {
  if (next != PortState::kRunning && probe_) {
    end_bus_scan(fmt::format("port {}: {}", to_string(next), reason), now);
  }
  if (next == state_ && reason == reason_) return;
  state_ = next;
  reason_ = std::move(reason);
  log_.with("PORT_STATE", std::string(to_string(next)))
      .info("port {}: {}", to_string(next), reason_);
  observer_.on_port_state(next, reason_, now);
}

void Scanner::start(TimePoint now) {
  if (state_ != PortState::kStopped) return;
  unconfigured_last_heard_.fill(kNever);
  stray_strobe_release_.fill(kNever);
  answering_other_master_.reset();
  set_state(PortState::kCheckingMac,
            fmt::format("checking that no other node has MAC {}", config_.master_mac.value()), now);
  sink_.send(mac_check_.start(now), now);
}

void Scanner::begin_scanning(TimePoint now) {
  set_state(PortState::kRunning, "MAC check passed: scanning", now);
  // Stagger first allocations and poll slots across the scan list so the bus
  // sees an even load rather than bursts.
  const auto count = static_cast<std::int64_t>(nodes_.size());
  for (std::int64_t i = 0; i < count; ++i) {
    Node& node = *nodes_[static_cast<std::size_t>(i)];
    // A node put back where one is still to be released starts after it.
    if (leaving(node.mac())) continue;
    const Duration period = node.config().poll_period;
    node.set_poll_phase(now + period * i / count);
    node.start(now, now + milliseconds(2) * i);
  }
  schedule_strobes(now);
  for (auto& n : leaving_) n->release_after_loss(now);
}

void Scanner::recheck_mac(std::string_view why, TimePoint now) {
  if (state_ == PortState::kCheckingMac) {
    // The check under way may have gone out on a bus that was not there:
    // it starts again.
    set_state(PortState::kCheckingMac,
              fmt::format("{}: checking again that no other node has MAC {}", why,
                          config_.master_mac.value()),
              now);
    sink_.send(mac_check_.start(now), now);
    return;
  }
  if (state_ != PortState::kRunning) return;
  // Whatever the nodes had is gone with the bus: they are allocated afresh
  // once the master's MAC is checked again.
  for (auto& n : nodes_) n->suspend(fmt::format("{}: the master checks its MAC again", why), now);
  // Those being taken out are released once the master is back (the
  // device may have kept their connections through a short loss).
  for (auto& n : leaving_) {
    n->suspend(fmt::format("{}: to be released once the master is back on the bus", why), now);
  }
  set_state(PortState::kCheckingMac,
            fmt::format("{}: checking again that no other node has MAC {}", why,
                        config_.master_mac.value()),
            now);
  sink_.send(mac_check_.start(now), now);
}

void Scanner::stop(TimePoint now) {
  if (state_ == PortState::kRunning) {
    set_state(PortState::kStopping, "orderly shutdown: idling and releasing nodes", now);
    // A node put back where one is still released stops after it (reap):
    // a MAC's events come from one node at a time.
    for (auto& n : nodes_) {
      if (!leaving(n->mac())) n->begin_shutdown(now);
    }
    finish_stopping(now);
  } else if (state_ == PortState::kCheckingMac) {
    drop_leaving("port stopped", now);
    for (auto& n : nodes_) n->halt("port stopped", now);
    set_state(PortState::kStopped, "stopped during the MAC check", now);
  }
}

bool Scanner::stopped() const {
  if (state_ == PortState::kStopped || state_ == PortState::kDuplicateMac) return true;
  if (state_ != PortState::kStopping) return false;
  const auto done = [](const auto& n) { return n->stopped(); };
  return std::all_of(nodes_.begin(), nodes_.end(), done) &&
         std::all_of(leaving_.begin(), leaving_.end(), done);
}

Node* Scanner::find(MacId mac) { return by_mac_[mac.value()]; }

const Node* Scanner::node(MacId mac) const { return by_mac_[mac.value()]; }

void Scanner::on_frame(const can::CanFrame& frame, TimePoint rx_time) {
  dispatch(frame, rx_time);
  if (!leaving_.empty()) reap(rx_time);
  finish_stopping(rx_time);
}

void Scanner::finish_stopping(TimePoint now) {
  if (state_ == PortState::kStopping && stopped()) {
    set_state(PortState::kStopped, "all nodes released", now);
  }
}

void Scanner::dispatch(const can::CanFrame& frame, TimePoint rx_time) {
  ++counters_.frames_received;
  if (state_ == PortState::kStopped || state_ == PortState::kDuplicateMac) return;
  auto id = decode_identifier(frame.id);
  if (!id) {
    ++counters_.invalid_identifiers;
    foreign_log_limit_.warn(log_, rx_time, "frame with a non-DeviceNet identifier 0x{:03X} ignored",
                            frame.id);
    return;
  }
  const Bytes payload = frame.payload();

  if (id->group == MessageGroup::k2 &&
      id->message_id == static_cast<std::uint8_t>(Group2Message::kDuplicateMacCheck)) {
    auto message = decode_duplicate_mac(payload);
    if (!message) {
      ++counters_.foreign_frames;
      return;
    }
    if (id->mac == config_.master_mac) {
      if (auto reply = mac_check_.on_message(*message)) sink_.send(*reply, rx_time);
      if (mac_check_.state() == DuplicateMacCheck::State::kDuplicate) {
        const std::string reason =
            fmt::format("another node (vendor {}, serial {}) has the master's MAC {}",
                        message->vendor_id, message->serial_number, config_.master_mac.value());
        log_.error("{}: port stopped", reason);
        drop_leaving("port stopped: duplicate master MAC", rx_time);
        for (auto& n : nodes_) n->halt("port stopped: duplicate master MAC", rx_time);
        set_state(PortState::kDuplicateMac, reason, rx_time);
      }
      return;
    }
    if (Node* n = route(id->mac)) {
      if (!message->response) n->on_duplicate_mac_request(rx_time);
    } else {
      // Powering up, it has no master (yet).
      if (!message->response) answering_other_master_.reset(id->mac.value());
      heard_unconfigured(id->mac,
                         message->response ? "answering a duplicate MAC ID check"
                                           : "checking its MAC ID (powering up)",
                         rx_time);
    }
    return;
  }

  if (state_ == PortState::kCheckingMac) return;

  if (id->group == MessageGroup::k1) {
    // A slave's I/O message: its node's, or from a MAC another master holds.
    struct IoMessage {
      Group1Message message;
      void (Node::*take)(Bytes, TimePoint);
      const char* heard_as;  // null: see stray_strobe_response()
    };
    static constexpr IoMessage kIoMessages[] = {
        {Group1Message::kSlavePollResponse, &Node::on_poll_response,
         "answering another master's poll"},
        {Group1Message::kSlaveCosCyclic, &Node::on_cos_message,
         "producing for another master (change of state)"},
        {Group1Message::kSlaveBitStrobeResponse, &Node::on_strobe_response, nullptr},
    };
    for (const IoMessage& m : kIoMessages) {
      if (id->message_id != static_cast<std::uint8_t>(m.message)) continue;
      if (Node* n = route(id->mac)) {
        (n->*m.take)(payload, rx_time);
      } else if (m.heard_as == nullptr) {
        ++counters_.unknown_nodes;
        stray_strobe_response(id->mac, rx_time);
      } else {
        ++counters_.unknown_nodes;
        answering_other_master_.set(id->mac.value());
        heard_unconfigured(id->mac, m.heard_as, rx_time);
      }
      return;
    }
  }
  if (id->group == MessageGroup::k2 &&
      id->message_id == static_cast<std::uint8_t>(Group2Message::kSlaveExplicitResponse)) {
    if (Node* n = route(id->mac)) {
      n->on_explicit_frame(payload, rx_time);
      return;
    }
    // The header names the master the response is for.
    const bool for_this_master =
        !payload.empty() && decode_header(payload[0]).mac == config_.master_mac;
    if (for_this_master && probe_ && probe_->on_frame(id->mac, payload, rx_time)) {
      if (probe_->done()) end_bus_scan({}, rx_time);
      return;
    }
    ++counters_.unknown_nodes;
    // An explicit answer to another master does not say that master holds
    // the node (it may be scanning too): only its polls do.
    heard_unconfigured(id->mac,
                       for_this_master ? "answering this master's bus scan late"
                                       : "answering another master's explicit request",
                       rx_time);
    return;
  }
  // Requests from other masters, other connection types, Group 3 and 4.
  ++counters_.foreign_frames;
}

std::bitset<MacId::kMax + 1> Scanner::unconfigured_heard(TimePoint now) const {
  std::bitset<MacId::kMax + 1> heard;
  for (std::size_t mac = 0; mac < unconfigured_last_heard_.size(); ++mac) {
    const TimePoint last = unconfigured_last_heard_[mac];
    if (last != kNever && now - last < kUnconfiguredMemory) heard.set(mac);
  }
  return heard;
}

void Scanner::heard_unconfigured(MacId mac, std::string_view how, TimePoint at) {
  TimePoint& last = unconfigured_last_heard_[mac.value()];
  const bool listed = last != kNever && at - last < kUnconfiguredMemory;
  last = at;
  if (listed) return;
  log_.with("MAC", std::to_string(mac.value()))
      .warn(
          "a node at MAC {}, which the configuration does not have, was heard {}: a MAC switch "
          "set wrong, or a node to configure",
          mac.value(), how);
  observer_.on_unconfigured_node(mac, at);
}

void Scanner::on_timer(TimePoint now) {
  if (state_ == PortState::kCheckingMac) {
    if (now >= mac_check_.deadline()) {
      if (auto again = mac_check_.on_timer(now)) sink_.send(*again, now);
      if (mac_check_.state() == DuplicateMacCheck::State::kOnline) begin_scanning(now);
    }
    return;
  }
  if (state_ != PortState::kRunning && state_ != PortState::kStopping) return;
  if (probe_ && now >= probe_->deadline()) {
    probe_->on_timer(now);
    if (probe_->done()) end_bus_scan({}, now);
  }
  for (auto& n : leaving_) {
    if (now >= n->deadline()) n->on_timer(now);
  }
  if (!leaving_.empty()) reap(now);
  bool polled = false;
  for (auto& n : nodes_) {
    if (now < n->deadline()) continue;
    const std::uint64_t before = n->counters().polls;
    n->on_timer(now);
    polled = polled || n->counters().polls != before;
  }
  if (polled && config_.poll_batch_window > Duration::zero()) {
    for (auto& n : nodes_) {
      const Duration window = std::min(config_.poll_batch_window, n->config().poll_period / 4);
      if (n->next_poll() <= now + window) n->poll_ahead(now);
    }
  }
  if (now >= next_strobe_) strobe(now);
  finish_stopping(now);
}

TimePoint Scanner::next_deadline() const {
  if (state_ == PortState::kCheckingMac) return mac_check_.deadline();
  if (state_ != PortState::kRunning && state_ != PortState::kStopping) return kNever;
  TimePoint t = probe_ ? probe_->deadline() : kNever;
  for (const auto& n : nodes_) t = std::min(t, n->deadline());
  for (const auto& n : leaving_) t = std::min(t, n->deadline());
  return std::min(t, next_strobe_);
}

Duration Scanner::strobe_period() const {
  Duration period = Duration::zero();
  for (const auto& n : nodes_) {
    const auto& in = n->config().profile.input_connection;
    if (!in || !in->strobed()) continue;
    if (period == Duration::zero() || n->config().poll_period < period) {
      period = n->config().poll_period;
    }
  }
  return period;
}

void Scanner::strobe(TimePoint now) {
  const Duration period = state_ == PortState::kRunning ? strobe_period() : Duration::zero();
  if (period == Duration::zero()) {
    next_strobe_ = kNever;
    return;
  }
  // Slots one period apart, as polls are: a late wake-up does not delay the
  // next one (a wake-up a period or more late starts them again from now).
  strobe_slot_ = next_strobe_;
  next_strobe_ = strobe_slot_ + period;
  if (next_strobe_ <= now) next_strobe_ = now + period;
  // One command for every strobed node, each one's bit 0 (no strobe
  // outputs); none while no node has its bit-strobe connection.
  if (std::none_of(nodes_.begin(), nodes_.end(), [](const auto& n) { return n->strobed(); })) {
    return;
  }
  can::CanFrame frame;
  frame.id = group2_id(config_.master_mac, Group2Message::kMasterBitStrobeCommand);
  frame.len = kBitStrobeCommandSize;
  sink_.send(frame, now);
  ++counters_.bit_strobes;
  last_strobe_sent_ = now;
}

void Scanner::schedule_strobes(TimePoint now) {
  const Duration period = strobe_period();
  if (period == Duration::zero()) {
    next_strobe_ = kNever;
  } else {
    // One period (the scan list's, now) after the last slot, at once if none.
    next_strobe_ = strobe_slot_ == kNever ? now : strobe_slot_ + period;
  }
}

void Scanner::stray_strobe_response(MacId mac, TimePoint at) {
  // A Group 1 message 14 names no master, and a slave answers only its
  // owner's strobes. While this port strobes (its last command within a
  // period), a node the scan list does not have that answers is taken for a
  // bit-strobe connection this master left allocated (its Release lost, or
  // the node taken out of the configuration while the master was away),
  // kept alive by the strobes of the others: released, at most once per
  // kStrayStrobeReleaseInterval while it goes on (a device another master
  // owns refuses that Release). Otherwise it answers another master.
  const Duration period = strobe_period();
  if (last_strobe_sent_ == kNever || period == Duration::zero() ||
      at - last_strobe_sent_ > period) {
    answering_other_master_.set(mac.value());
    heard_unconfigured(mac, "answering another master's bit-strobe", at);
    return;
  }
  heard_unconfigured(mac, "answering this port's bit-strobe commands", at);
  TimePoint& sent = stray_strobe_release_[mac.value()];
  if (sent != kNever && at - sent < kStrayStrobeReleaseInterval) return;
  sent = at;
  if (auto frame = make_release_frame(mac, config_.master_mac, allocation::kBitStrobe)) {
    log_.info("MAC {} answers this port's bit-strobe commands: its bit-strobe connection released",
              mac.value());
    sink_.send(*frame, at);
  }
}

Status Scanner::scan_bus(TimePoint now) {
  if (state_ != PortState::kRunning) return Errc::kStopped;
  if (probe_) return Errc::kBusy;
  std::vector<MacId> ask;
  std::vector<MacId> others;
  const auto heard = unconfigured_heard(now);
  for (unsigned m = 0; m <= MacId::kMax; ++m) {
    const MacId mac = *MacId::from(m);
    if (mac == config_.master_mac || route(mac)) continue;
    if (heard.test(m) && answering_other_master_.test(m)) {
      others.push_back(mac);
    } else {
      ask.push_back(mac);
    }
  }
  log_.info(
      "bus scan: asking {} MACs the scan list does not have ({} heard answering another "
      "master's polls are not asked)",
      ask.size(), others.size());
  probe_ = std::make_unique<BusProbe>(
      config_.master_mac, std::move(ask), others,
      BusProbe::Config{config_.scan_response_timeout, config_.explicit_messaging.response_timeout},
      sink_);
  probe_started_ = now;
  probe_->start(now);
  if (probe_->done()) end_bus_scan({}, now);
  return {};
}

void Scanner::end_bus_scan(std::string_view why, TimePoint now) {
  if (!probe_) return;
  if (!why.empty()) probe_->cancel(why, now);
  BusScan scan;
  scan.findings = probe_->findings();
  scan.started = probe_started_;
  scan.finished = now;
  scan.error = std::string(why);
  probe_.reset();
  const auto count = [&](ScanOutcome o) {
    return std::count_if(scan.findings.begin(), scan.findings.end(),
                         [o](const ScanFinding& f) { return f.outcome == o; });
  };
  log_.info("bus scan {}: {} nodes answered, {} held by another master, {} silent{}",
            why.empty() ? "done" : "ended early", count(ScanOutcome::kIdentified),
            count(ScanOutcome::kOwnedByOtherMaster) + count(ScanOutcome::kAnsweringOtherMaster),
            count(ScanOutcome::kNoAnswer), why.empty() ? "" : fmt::format(" ({})", why));
  observer_.on_bus_scan(scan, now);
}

std::string_view to_string(ScanOutcome outcome) noexcept {
  switch (outcome) {
    case ScanOutcome::kIdentified:
      return "identified";
    case ScanOutcome::kNoAnswer:
      return "no answer";
    case ScanOutcome::kRefused:
      return "refused";
    case ScanOutcome::kOwnedByOtherMaster:
      return "owned by another master";
    case ScanOutcome::kAnsweringOtherMaster:
      return "answering another master";
    case ScanOutcome::kNotAsked:
      return "not asked";
  }
  return "?";
}

Status Scanner::set_outputs(MacId mac, Bytes data, TimePoint now) {
  Node* n = find(mac);
  if (!n) return Errc::kOutOfRange;
  if (state_ == PortState::kStopping) return Errc::kStopped;
  return n->set_outputs(data, now);
}

Status Scanner::set_idle(MacId mac, bool idle, TimePoint now) {
  Node* n = find(mac);
  if (!n) return Errc::kOutOfRange;
  n->set_idle(idle, now);
  return {};
}

Result<std::uint32_t> Scanner::request_explicit(MacId mac, const RequestMessage& request,
                                                TimePoint now) {
  Node* n = find(mac);
  if (!n) return Errc::kOutOfRange;
  if (state_ != PortState::kRunning) return Errc::kStopped;
  const std::uint32_t id = next_request_id_;
  next_request_id_ = next_request_id_ + 1 >= Node::kInternalTag ? 1 : next_request_id_ + 1;
  if (auto s = n->request_explicit(id, request, now); !s) return s.error();
  return id;
}

}  // namespace dnbridge::devicenet
