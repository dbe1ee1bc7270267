// Node: the start-up's answers about its I/O connections: the poll
// connection's paths, sizes and expected packet rates, and the input
// connection (change of state, cyclic or bit-strobe): the handlers, what the
// requests take from the node, and when the optional steps apply. Where each
// verdict leads is the table's (kStartup, node_lifecycle.cpp).
#include <fmt/format.h>

#include <algorithm>

#include "bridge/cip/data_types.hpp"
#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/node_internal.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

namespace {

namespace conn = cip::connection;

// The EPR a Set of it returned (the device rounds it to its timer
// resolution), or the one asked when it returned none.
Duration returned_epr(const ExplicitResult& r, Duration asked) {
  const auto actual = read_uint(r.data.view());
  return actual && *actual > 0 ? milliseconds(*actual) : asked;
}

}  // namespace

// --- poll connection paths --------------------------------------------------------

bool Node::path_step_produced(Step step) const {
  return step == Step::kGetProducedPath || step == Step::kSetProducedPath;
}

Bytes Node::wanted_path(bool produced) const {
  return Bytes(produced ? config_.profile.produced_path : config_.profile.consumed_path);
}

bool Node::has_produced_path() const { return !config_.profile.produced_path.empty(); }

bool Node::has_consumed_path() const { return !config_.profile.consumed_path.empty(); }

void Node::ask_allocate_poll(Ask&, TimePoint) { poll_.allocation().requested = true; }

void Node::ask_produced_path(Ask& ask, TimePoint) { ask.value.assign(wanted_path(true)); }

void Node::ask_consumed_path(Ask& ask, TimePoint) { ask.value.assign(wanted_path(false)); }

// A path that differs is set (Verdict::kAlt); one that is right, next.
Node::Verdict Node::after_get_path(const ExplicitResult& r, TimePoint) {
  const bool produced = path_step_produced(last_step_);
  auto& in_force = produced ? produced_path_in_force_ : consumed_path_in_force_;
  in_force.clear();
  if (r.ok()) in_force.assign(r.data.view());
  const Bytes want = wanted_path(produced);
  if (r.ok() &&
      std::equal(in_force.view().begin(), in_force.view().end(), want.begin(), want.end())) {
    return Verdict::kNext;
  }
  return Verdict::kAlt;
}

Node::Verdict Node::after_set_path(const ExplicitResult& r, TimePoint) {
  const bool produced = path_step_produced(last_step_);
  auto& in_force = produced ? produced_path_in_force_ : consumed_path_in_force_;
  if (r.ok()) {
    in_force.assign(wanted_path(produced));
    return Verdict::kNext;
  }
  // The paths are fixed in some devices (the CDN127 manual's table lists
  // them Get only). What the device has may serve all the same: the sizes
  // decide, and the reason names both paths if they do not.
  const cip::AttributeRef target = target_of(last_step_);
  if (!path_refusal_.empty()) path_refusal_ += "; ";
  path_refusal_ += fmt::format(
      "device refused Set {} = {} ({}); it has {}", target.name, hex(wanted_path(produced)),
      status_text(r), in_force.empty() ? std::string("(unreadable)") : hex(in_force.view()));
  return Verdict::kNext;
}

// --- sizes, expected packet rates -------------------------------------------------

Node::Verdict Node::after_size(const ExplicitResult& r, TimePoint now) {
  const Step step = last_step_;
  const auto value = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  const bool produced = step == Step::kProducedSize || step == Step::kFallbackProducedSize;
  const bool fallback = step == Step::kFallbackProducedSize || step == Step::kFallbackConsumedSize;
  const char* which = produced ? "produced" : "consumed";
  const auto answer = [&] { return r.ok() ? "bad size " + hex(r.data.view()) : status_text(r); };
  if (!value) {
    if (!fallback && config_.profile.has_size_fallback) {
      // Connection 2 attributes 7/8 refused (older firmware answers 0x14,
      // attribute not supported): ask where the profile says the same sizes
      // are kept.
      size_refusal_ = fmt::format("{}: {}", size_attribute(produced, false), answer());
      log_.debug("poll {} size: {}; asking {}", which, size_refusal_,
                 size_attribute(produced, true));
      return Verdict::kAlt;
    }
    // The consumed size's own attribute was not asked when the produced
    // size's was refused: say so rather than name the other's refusal.
    const std::string first =
        !produced && produced_from_fallback_
            ? fmt::format("{} not asked ({})", size_attribute(false, false), size_refusal_)
            : size_refusal_;
    enter_fault(NodeState::kConfigurationFault,
                fallback ? fmt::format("cannot read the poll {} size: {}; fallback {}: {}", which,
                                       first, size_attribute(produced, true), answer())
                         : fmt::format("cannot read the poll {} size: {}: {}", which,
                                       size_attribute(produced, false), answer()),
                now);
    return Verdict::kStop;
  }
  if (produced) {
    produced_size_ = *value;
    produced_from_fallback_ = fallback;
    // A device that refused attribute 7 refuses 8 too: the fallback's row
    // asks the fallback for the consumed size straight away.
    return Verdict::kNext;
  }
  consumed_size_ = *value;
  consumed_from_fallback_ = fallback;
  return check_sizes(now);
}

std::string Node::size_attribute(bool produced, bool fallback) const {
  if (!fallback) {
    const cip::AttributeRef& a = produced ? conn::kPollProducedSize : conn::kPollConsumedSize;
    return fmt::format("Connection {} attribute {}", a.instance_id, a.attribute);
  }
  const auto& fb = config_.profile.size_fallback;
  return fmt::format("{} (class 0x{:02X}) instance {} attribute {}",
                     fb.object_name.empty() ? "object" : fb.object_name, fb.class_id,
                     fb.instance_id, produced ? fb.produced_attribute : fb.consumed_attribute);
}

Node::Verdict Node::check_sizes(TimePoint now) {
  const auto& p = config_.profile;
  if (*produced_size_ != p.produced_size || *consumed_size_ != p.consumed_size) {
    // Never guess which of the two is right: say both, where the device's
    // were read, and which path it refused to take.
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("poll sizes differ: the device produces {} B ({}) and consumes {} B "
                            "({}); the configuration expects {} B and {} B ({}){}{}",
                            *produced_size_, size_attribute(true, produced_from_fallback_),
                            *consumed_size_, size_attribute(false, consumed_from_fallback_),
                            p.produced_size, p.consumed_size, p.format_description,
                            path_refusal_.empty() ? "" : "; ", path_refusal_),
                now);
    return Verdict::kStop;
  }
  if (!path_refusal_.empty()) {
    log_.info("{}; the paths in force give the sizes the configuration needs: going on",
              path_refusal_);
  }
  return Verdict::kNext;
}

void Node::ask_explicit_epr(Ask& ask, TimePoint) {
  ask.value.assign(Bytes(uint_le(to_ms(config_.explicit_packet_rate))));
}

void Node::ask_poll_epr(Ask& ask, TimePoint) {
  // Setting EPR establishes the poll connection and starts the device's
  // 4 x EPR watchdog, so the first poll follows at once. A lost answer is
  // retried after 2 x EPR, while the connection lives.
  ask.value.assign(Bytes(uint_le(to_ms(config_.expected_packet_rate))));
  ask.timeout = std::min(client_.response_timeout(), 2 * config_.expected_packet_rate);
}

// The device rounds EPR to its timer resolution and returns the value it
// uses; every timeout that depends on EPR uses that value. A device that
// returns nothing keeps the value asked.
Node::Verdict Node::after_explicit_epr(const ExplicitResult& r, TimePoint) {
  keep_alive_.set_epr(returned_epr(r, config_.explicit_packet_rate));
  return Verdict::kNext;
}

Node::Verdict Node::after_poll_epr(const ExplicitResult& r, TimePoint) {
  const Duration asked = config_.expected_packet_rate;
  const Duration epr = returned_epr(r, asked);
  poll_.set_epr(epr);
  // A device that rounds the rate up beyond 4 poll periods makes a lost
  // connection noticed later than the configuration suggests: said once. (A
  // configured rate above that is the configuration's choice, not news.)
  if (epr > asked && epr > 4 * config_.poll_period && !epr_warned_) {
    epr_warned_ = true;
    log_.warn(
        "the device uses an expected packet rate of {} ms (asked {} ms), more than 4 x the "
        "poll period of {} ms: a lost connection is noticed only after {} ms",
        to_ms(epr), to_ms(asked), to_ms(config_.poll_period), 4 * to_ms(epr));
  }
  return Verdict::kNext;
}

// --- the input connection: change of state, cyclic or bit-strobe -------------------

// The input connection is set up once the poll connection's sizes are
// verified, and started (its EPR) right after the poll connection's:
// nothing runs between the poll connection's start and its first poll but
// that one Set.
bool Node::has_input() const { return config_.profile.input_connection.has_value(); }

bool Node::has_input_path() const {
  return has_input() && !config_.profile.input_connection->produced_path.empty();
}

bool Node::has_input_inhibit() const {
  const auto& in = config_.profile.input_connection;
  return in && in->kind == InputKind::kChangeOfState && in->inhibit.has_value();
}

bool Node::has_ack_handler() const {
  const auto& in = config_.profile.input_connection;
  return in && in->acknowledged && !in->strobed();
}

void Node::ask_allocate_cos(Ask& ask, TimePoint) {
  input_.allocation().requested = true;
  ask.choice = input_.choice();
}

void Node::ask_cos_release(Ask& ask, TimePoint) { ask.choice = input_.connection_bits(); }

void Node::ask_cos_path(Ask& ask, TimePoint) {
  ask.value.assign(Bytes(config_.profile.input_connection->produced_path));
}

void Node::ask_cos_inhibit(Ask& ask, TimePoint) {
  ask.value.assign(Bytes(uint_le(to_ms(*config_.profile.input_connection->inhibit))));
}

void Node::ask_cos_epr(Ask& ask, TimePoint now) {
  // Setting EPR starts production: a message may come before the answer.
  input_.start_consuming(now);
  // Right after the poll connection's start, bounded as its Set was.
  ask.value.assign(Bytes(uint_le(to_ms(input_.epr_asked()))));
  ask.timeout = std::min(client_.response_timeout(), 2 * poll_.epr());
}

Node::Verdict Node::after_allocate_cos(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    input_.allocation().allocated = true;
    return Verdict::kNext;
  }
  const std::string_view kind = to_string(config_.profile.input_connection->kind);
  return io_allocate_refused(
      r, now, fmt::format("Allocate of the {} connection (choice 0x{:02X})", kind, input_.choice()),
      fmt::format("; the node's connection = \"{}\" needs it", kind), input_.allocation());
}

// The answers to the input connection's set-up: what the device refuses but
// can do without is logged and the set-up goes on; a produced size other
// than the configuration's is a fault.
Node::Verdict Node::after_cos_path(const ExplicitResult& r, TimePoint) {
  if (!r.ok()) {
    const InputConnection& in = *config_.profile.input_connection;
    input_.set_path_refusal(fmt::format("; Set of {} to {} refused: {}", target_of(last_step_).name,
                                        hex(Bytes(in.produced_path)), status_text(r)));
    log_.info("{}: the size tells whether the device's own path serves",
              input_.path_refusal().substr(2));
  }
  return Verdict::kNext;
}

Node::Verdict Node::after_cos_inhibit(const ExplicitResult& r, TimePoint) {
  if (!r.ok()) {
    log_.warn("the device refused {} = {} ms ({}): it keeps its own", target_of(last_step_).name,
              to_ms(*config_.profile.input_connection->inhibit), status_text(r));
  }
  return Verdict::kNext;
}

Node::Verdict Node::after_cos_size(const ExplicitResult& r, TimePoint now) {
  const cip::AttributeRef target = target_of(last_step_);
  const auto want = config_.profile.input_connection->produced_size;
  const auto size = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  if (!r.ok()) {
    log_.info("{} not read ({}): every message's size is checked", target.name, status_text(r));
  } else if (!size || *size != want) {
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} is {}, the configuration expects {} bytes{}", target.name,
                            size ? fmt::format("{} bytes", *size) : hex(r.data.view()), want,
                            input_.path_refusal()),
                now);
    return Verdict::kStop;
  }
  return Verdict::kNext;
}

// The Acknowledge Handler's timer and retry limit: the defaults where the
// device does not tell.
Node::Verdict Node::after_ack_setting(const ExplicitResult& r, TimePoint) {
  const bool timer = last_step_ == Step::kAckTimer;
  const auto v = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  if (!v) {
    input_.note_ack_handler_unread();
    log_.info("{} not read ({}): taking the default, {}", target_of(last_step_).name,
              r.ok() ? hex(r.data.view()) : status_text(r), timer ? "20 ms" : "1 retry");
  } else if (timer) {
    input_.set_ack_timer(milliseconds(*v));
  } else {
    input_.set_retry_limit(static_cast<std::uint8_t>(std::min<std::uint32_t>(*v, 255)));
  }
  return Verdict::kNext;
}

// As the poll's: the value the device returned is the one it uses.
Node::Verdict Node::after_cos_epr(const ExplicitResult& r, TimePoint) {
  input_.set_epr(returned_epr(r, input_.epr_asked()));
  return Verdict::kNext;
}

}  // namespace dnbridge::devicenet
