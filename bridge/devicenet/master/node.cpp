// Node: its state, its timers and frames, its keep-alive and health, going
// online, losing it, faults and shutdown, and the explicit requests it
// carries for others.
#include "bridge/devicenet/master/node.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/cip/identity_health.hpp"
#include "bridge/devicenet/master/node_internal.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

namespace {

namespace ident = cip::identity;

// The node's explicit messaging: the port's, with the node's own response
// timeout for a slow device.
ExplicitClient::Config client_config(const NodeConfig& node, const ScannerConfig& port) {
  ExplicitClient::Config c = port.explicit_messaging;
  if (node.explicit_response_timeout) c.response_timeout = *node.explicit_response_timeout;
  return c;
}

}  // namespace

Node::Node(NodeConfig config, const ScannerConfig& port, can::FrameSink& sink,
           ScannerObserver& observer, Logger log)
    : config_(std::move(config)),
      port_(port),
      sink_(sink),
      observer_(observer),
      log_(std::move(log)),
      client_(port.master_mac, config_.mac, client_config(config_, port), sink, *this),
      retry_delay_(port.allocate_retry_min),
      jitter_state_(0x9E3779B9u ^ (static_cast<std::uint32_t>(config_.mac.value()) * 0x85EBCA6Bu)),
      poll_(config_, port, sink, counters_, *this),
      input_(config_, sink, counters_, *this),
      keep_alive_(config_.explicit_packet_rate) {}

void Node::apply_port_timings() {
  client_.set_response_timeout(client_config(config_, port_).response_timeout);
}

void Node::retire(std::string why, TimePoint now) {
  reports_data_ = false;
  shutdown_why_ = std::move(why);
  begin_shutdown(now);
}

void Node::start(TimePoint now, TimePoint first_attempt) {
  started_ = true;
  shutting_down_ = false;
  retry_at_ = first_attempt;
  retry_delay_ = port_.allocate_retry_min;
  set_state(NodeState::kAbsent, "waiting for the first Allocate", now);
}

void Node::set_state(NodeState next, std::string reason, TimePoint now) {
  // A fault state stays while the periodic re-check walks through the life
  // cycle again; only its outcome (online, absent, another fault) is news.
  const bool intermediate = next == NodeState::kIdentifying || next == NodeState::kConfiguring ||
                            next == NodeState::kVerifying;
  if (is_fault(state_) && intermediate) return;
  if (next == state_ && reason == reason_) return;
  const NodeState from = state_;
  state_ = next;
  reason_ = std::move(reason);
  if (log_.enabled(LogLevel::kDebug)) {
    log_.with("NODE_STATE", std::string(to_string(next)))
        .debug("{} -> {}: {}", to_string(from), to_string(next), reason_);
  }
  observer_.on_node_state(config_.mac, from, next, reason_, now);
}

void Node::lose(std::string reason, TimePoint now) {
  if (state_ == NodeState::kOnline) ++counters_.reconnects;
  forget_connections(Errc::kNotConnected, now);
  if (shutting_down_) {
    set_state(NodeState::kStopped, "stopped: " + reason, now);
    return;
  }
  set_state(NodeState::kAbsent, std::move(reason), now);
  // The delay grows with every loss until the node is online again: a node
  // that drops out repeatedly during start-up is not re-allocated in a loop.
  retry_at_ = now + next_backoff();
}

Duration Node::next_backoff() {
  const Duration base = retry_delay_;
  retry_delay_ = std::min(retry_delay_ * 2, port_.allocate_retry_max);
  // Jitter of -25..+25 %: nodes that failed together do not retry together.
  jitter_state_ ^= jitter_state_ << 13;
  jitter_state_ ^= jitter_state_ >> 17;
  jitter_state_ ^= jitter_state_ << 5;
  // offset = span x fraction - span / 2, fraction in [0, 1): any base, no
  // bias, no overflow.
  const Duration::rep span = base.count() / 2;
  const double fraction = static_cast<double>(jitter_state_) / 4294967296.0;
  const auto offset = static_cast<Duration::rep>(static_cast<double>(span) * fraction) - span / 2;
  return base + Duration(offset);
}

void Node::enter_fault(NodeState fault, std::string reason, TimePoint now) {
  if (state_ == NodeState::kOnline) {
    ++counters_.reconnects;
    // Outputs to the device's idle state before the connections go.
    poll_.send_idle_before_release(now);
  }
  poll_.stop();
  keep_alive_.stop();
  input_.stop();
  set_state(fault, std::move(reason), now);
  retry_at_ = now + port_.fault_recheck;
  // Leave a device that is not ours to poll unowned, so that its own
  // connection timeout puts it in its safe state.
  if (connected_) release(Step::kReleaseFault, held_connections(), now);
}

void Node::record(NodeError::Kind kind, TimePoint now, std::uint32_t got, std::uint32_t expected) {
  last_error_.kind = kind;
  last_error_.at = now;
  last_error_.got = got;
  last_error_.expected = expected;
  last_error_.general_status = cip::GeneralStatus::kSuccess;
  last_error_.additional_status = cip::kNoAdditionalCode;
}

void Node::record_device_error(const ExplicitResult& result, TimePoint now) {
  record(NodeError::Kind::kDeviceError, now);
  last_error_.general_status = result.general_status;
  last_error_.additional_status = result.additional_status;
}

void Node::begin_shutdown(TimePoint now) {
  if (shutting_down_) return;
  shutting_down_ = true;
  retry_at_ = kNever;
  poll_.stop_slots();
  keep_alive_.stop();
  step_ = Step::kNone;
  client_.cancel_all(Errc::kStopped, now);
  if (state_ == NodeState::kOnline) {
    // Outputs to the device's own idle state first: one idle poll (after the
    // one outstanding, if any); the Release follows its answer or timeout.
    // The minimum gap of polls for changed outputs does not hold it back: it
    // is one poll per node, so it cannot flood the bus, and a delay would
    // only leave the device in its commanded state longer. It supersedes a
    // poll held back by the gap (shutdown stops the node's timers).
    poll_.force_idle();
    if (!poll_.outstanding()) poll_.send(now);
    return;
  }
  if (connected_) {
    release(Step::kReleaseShutdown, held_connections(), now);
    return;
  }
  set_state(NodeState::kStopped, shutdown_why_, now);
}

void Node::release_for_shutdown(TimePoint now) {
  if (step_ == Step::kReleaseShutdown || state_ == NodeState::kStopped) return;
  poll_.drop_outstanding();
  release(Step::kReleaseShutdown, held_connections(), now);
}

void Node::forget_connections(Errc why, TimePoint now) {
  retry_at_ = kNever;
  poll_.stop();
  keep_alive_.stop();
  step_ = Step::kNone;
  connected_ = false;
  poll_.allocation().forget();
  input_.allocation().forget();
  input_.stop();
  client_.cancel_all(why, now);
}

void Node::halt(std::string_view reason, TimePoint now) {
  shutting_down_ = true;
  forget_connections(Errc::kStopped, now);
  set_state(NodeState::kStopped, std::string(reason), now);
}

void Node::suspend(std::string_view reason, TimePoint now) {
  if (!started_) return;  // nothing to forget; it waits for start() anyway
  if (state_ == NodeState::kOnline) ++counters_.reconnects;
  forget_connections(Errc::kNotConnected, now);
  set_state(NodeState::kAbsent, std::string(reason), now);
}

void Node::on_explicit_frame(Bytes payload, TimePoint now) {
  const auto before = client_.counters();
  client_.on_frame(payload, now);
  const auto& after = client_.counters();
  if (after.malformed_frames == before.malformed_frames &&
      after.unexpected_frames == before.unexpected_frames) {
    return;
  }
  error_log_limit_.warn(
      log_, now, "{} explicit frame ignored: {}",
      after.malformed_frames != before.malformed_frames ? "malformed" : "unexpected", hex(payload));
}

void Node::on_duplicate_mac_request(TimePoint now) {
  // A node checks its MAC only at power-up: whatever connections the master
  // thought it had are gone.
  if (connected_ && state_ != NodeState::kStopped && !shutting_down_) {
    lose("the node restarted (duplicate MAC ID check seen)", now);
  }
}

void Node::on_timer(TimePoint now) {
  if (now >= client_.deadline()) client_.on_timer(now);
  if (now >= retry_at_ && !shutting_down_) attempt_allocate(now);
  if (state_ != NodeState::kOnline) return;

  if (now >= poll_.response_deadline()) {
    poll_.give_up();
    ++counters_.timeouts;
    record(NodeError::Kind::kPollTimeout, now);
    // A stopping node's poll went unanswered: its idle poll next, if the
    // one outstanding was not it; the Release once the idle poll is answered
    // or goes unanswered.
    if (shutting_down_) continue_shutdown(now);
  }
  if (shutting_down_) return;
  // The device drops the connection after 4 x EPR without a poll; the master
  // drops the node after 4 x EPR without a response.
  if (poll_.watchdog_expired(now)) {
    record(NodeError::Kind::kConnectionLost, now);
    lose(fmt::format("no poll response for {} ms (4 x EPR)",
                     std::chrono::duration_cast<milliseconds>(poll_.silence(now)).count()),
         now);
    return;
  }
  // Likewise 4 x EPR without a message of the input connection (change of
  // state or cyclic, heartbeats included; bit-strobe responses).
  if (input_.watchdog_expired(now)) {
    const InputConnection& in = *input_.configured();
    // Messages that came but were refused say why none was taken.
    const unsigned refused_count = input_.errors_in_a_row();
    const std::string refused =
        refused_count > 0
            ? fmt::format("; the last {} were refused: {}", refused_count, last_error_.describe())
            : std::string();
    ++counters_.heartbeats_missed;
    record(in.strobed() ? NodeError::Kind::kStrobeMissed : NodeError::Kind::kHeartbeatMissed, now);
    lose_and_release(
        fmt::format("no {} {} for {} ms (4 x EPR of {} ms){}", to_string(in.kind),
                    in.strobed() ? "response" : "message",
                    std::chrono::duration_cast<milliseconds>(now - input_.last_message()).count(),
                    to_ms(input_.settings()->expected_packet_rate), refused),
        now);
    return;
  }
  poll_.on_timer(now);
  // The keep-alive has its own place in the client's queue (request_explicit
  // leaves it); one still unanswered is not doubled.
  if (const cip::AttributeRef* read = keep_alive_.on_timer(now, step_ == Step::kKeepAlive)) {
    get(Step::kKeepAlive, *read, now);
  }
}

TimePoint Node::deadline() const {
  TimePoint t = client_.deadline();
  if (state_ == NodeState::kOnline) t = std::min(t, poll_.response_deadline());
  if (shutting_down_) return t;
  t = std::min(t, retry_at_);
  if (state_ == NodeState::kOnline) {
    t = std::min({t, poll_.timers_deadline(), keep_alive_.next()});
    t = std::min(t, input_.watchdog_deadline());
  }
  return t;
}

// --- keep-alive, health, going online ---------------------------------------

void Node::on_keepalive_result(const ExplicitResult& r, TimePoint now) {
  if (r.ok() || r.error == Errc::kDeviceError) {
    if (r.ok() && !keep_alive_.reads_status() && r.data.size() == 1) {
      identity_.state = r.data[0];
      if (device_state_ != r.data[0]) {
        device_state_ = r.data[0];
        observer_.on_device_state(config_.mac, r.data[0], now);
      }
    }
    if (r.ok() && keep_alive_.reads_status() && r.data.size() == 2) {
      const auto status = static_cast<std::uint16_t>(*read_uint(r.data.view()));
      if (identity_.status != status) {
        identity_.status = status;
        note_minor_faults();
        observer_.on_node_identity(config_.mac, identity_, now);
      }
    }
    if (r.ok() && !check_health(now)) return;
    return;
  }
  // The device drops the explicit connection after 4 x EPR without a
  // request; single lost frames must not be taken for that. Try again at
  // once, and give up only when nothing has come back for that long.
  if (keep_alive_.lost(now)) {
    lose(fmt::format("explicit connection lost: no answer for {} ms (4 x EPR; {})",
                     std::chrono::duration_cast<milliseconds>(keep_alive_.silence(now)).count(),
                     status_text(r)),
         now);
    return;
  }
  keep_alive_.again(now);
}

void Node::note_minor_faults() {
  std::string minor = ident::minor_faults(identity_.status.value_or(0));
  if (minor == minor_faults_) return;
  if (!minor.empty()) log_.warn("the device reports a {}", minor);
  if (minor.empty()) log_.info("the device's minor faults cleared");
  minor_faults_ = std::move(minor);
}

bool Node::check_health(TimePoint now) {
  const auto major = ident::major_fault(identity_.status, identity_.state);
  if (!major) return true;
  device_fault(fmt::format("the device reports a {}; re-checked every {} ms", *major,
                           std::chrono::duration_cast<milliseconds>(port_.fault_recheck).count()),
               now);
  return false;
}

void Node::device_fault(std::string reason, TimePoint now) {
  enter_fault(NodeState::kDeviceFault, std::move(reason), now);
}

void Node::lose_and_release(std::string reason, TimePoint now) {
  // The poll connection lives: the outputs go to the device's idle state at
  // once rather than after its own watchdog, and what the device holds is
  // released (the node is allocated afresh after the back-off).
  if (state_ == NodeState::kOnline) poll_.send_idle_before_release(now);
  const std::uint8_t held = held_connections();
  lose(std::move(reason), now);
  if (held != 0) release(Step::kReleaseFault, held, now);
}

void Node::go_online(TimePoint now) {
  retry_delay_ = port_.allocate_retry_min;
  input_.reset_errors();
  poll_.start(now);
  keep_alive_.start(now);
  std::string reason =
      fmt::format("polled every {} ms; EPR {} ms (explicit {} ms); {} B out, {} B in",
                  std::chrono::duration_cast<milliseconds>(config_.poll_period).count(),
                  std::chrono::duration_cast<milliseconds>(poll_.epr()).count(),
                  std::chrono::duration_cast<milliseconds>(keep_alive_.epr()).count(),
                  config_.profile.consumed_size, config_.profile.produced_size);
  if (produced_from_fallback_ || consumed_from_fallback_) {
    // Worth knowing about a device: it refused Connection 2 attributes 7/8.
    reason +=
        fmt::format(" (sizes read from {} and {})", size_attribute(true, produced_from_fallback_),
                    size_attribute(false, consumed_from_fallback_));
  }
  reason += input_.describe();
  if (!keep_alive_.state_supported()) reason += "; Identity.State not supported: state unknown";
  set_state(NodeState::kOnline, std::move(reason), now);
  // Outputs set before the node came online go out with the first poll.
  poll_.send(now);
}

Status Node::request_explicit(std::uint32_t request_id, const RequestMessage& request,
                              TimePoint now) {
  if ((request_id & kInternalTag) != 0) return Errc::kOutOfRange;
  if (!connected_ || shutting_down_) return Errc::kNotConnected;
  // Two places stay free for the life cycle and the keep-alive.
  if (client_.queued() + 2 > ExplicitClient::kQueueCapacity) return Errc::kBusy;
  return client_.submit(request_id, request, false, now);
}

}  // namespace dnbridge::devicenet
