// Node: the start-up's answers about its I/O connections: the poll
// connection's paths, sizes and expected packet rates, and the input
// connection (change of state, cyclic or bit-strobe). The steps themselves
// are the table of node_lifecycle.cpp.
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

Node::Step Node::after_path(bool produced, TimePoint now) {
  if (produced && !config_.profile.consumed_path.empty()) return Step::kGetConsumedPath;
  return begin_verify(now);
}

Node::Step Node::after_get_path(const ExplicitResult& r, TimePoint now) {
  const bool produced = path_step_produced(last_step_);
  auto& in_force = produced ? produced_path_in_force_ : consumed_path_in_force_;
  in_force.clear();
  if (r.ok()) in_force.assign(r.data.view());
  const Bytes want = wanted_path(produced);
  if (r.ok() &&
      std::equal(in_force.view().begin(), in_force.view().end(), want.begin(), want.end())) {
    return after_path(produced, now);
  }
  return produced ? Step::kSetProducedPath : Step::kSetConsumedPath;
}

Node::Step Node::after_set_path(const ExplicitResult& r, TimePoint now) {
  const bool produced = path_step_produced(last_step_);
  auto& in_force = produced ? produced_path_in_force_ : consumed_path_in_force_;
  if (r.ok()) {
    in_force.assign(wanted_path(produced));
    return after_path(produced, now);
  }
  // The paths are fixed in some devices (the CDN127 manual's table lists
  // them Get only). What the device has may serve all the same: the sizes
  // decide, and the reason names both paths if they do not.
  const cip::AttributeRef target = target_of(last_step_);
  if (!path_refusal_.empty()) path_refusal_ += "; ";
  path_refusal_ += fmt::format(
      "device refused Set {} = {} ({}); it has {}", target.name, hex(wanted_path(produced)),
      status_text(r), in_force.empty() ? std::string("(unreadable)") : hex(in_force.view()));
  return after_path(produced, now);
}

// --- sizes, expected packet rates -------------------------------------------------

Node::Step Node::begin_verify(TimePoint) {
  produced_size_.reset();
  consumed_size_.reset();
  produced_from_fallback_ = consumed_from_fallback_ = false;
  size_refusal_.clear();
  return Step::kProducedSize;
}

Node::Step Node::after_size(const ExplicitResult& r, TimePoint now) {
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
      return produced ? Step::kFallbackProducedSize : Step::kFallbackConsumedSize;
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
    return Step::kNone;
  }
  if (produced) {
    produced_size_ = *value;
    produced_from_fallback_ = fallback;
    // A device that refused attribute 7 refuses 8 too: ask the fallback for
    // the consumed size straight away.
    return fallback ? Step::kFallbackConsumedSize : Step::kConsumedSize;
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

Node::Step Node::check_sizes(TimePoint now) {
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
    return Step::kNone;
  }
  if (!path_refusal_.empty()) {
    log_.info("{}; the paths in force give the sizes the configuration needs: going on",
              path_refusal_);
  }
  return config_.profile.input_connection ? Step::kAllocateCos : Step::kExplicitEpr;
}

Node::Step Node::after_epr(const ExplicitResult& r, TimePoint) {
  const bool poll = last_step_ == Step::kPollEpr;
  // The device rounds EPR to its timer resolution and returns the value it
  // uses; every timeout that depends on EPR uses that value. A device that
  // returns nothing keeps the value asked.
  const Duration asked = poll ? config_.expected_packet_rate : config_.explicit_packet_rate;
  const Duration epr = returned_epr(r, asked);
  if (!poll) {
    keep_alive_.set_epr(epr);
    return Step::kPollEpr;
  }
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
  return config_.profile.input_connection ? Step::kCosEpr : Step::kOnline;
}

// --- the input connection: change of state, cyclic or bit-strobe -------------------

// The input connection is set up once the poll connection's sizes are
// verified, and started (its EPR) right after the poll connection's:
// nothing runs between the poll connection's start and its first poll but
// that one Set. A bit-strobe connection has no inhibit time and no
// Acknowledge Handler.
Node::Step Node::cos_step_after(Step step) const {
  if (step == Step::kCosEpr) return Step::kOnline;
  static constexpr Step kOrder[] = {Step::kAllocateCos, Step::kSetCosPath, Step::kCosInhibit,
                                    Step::kCosSize,     Step::kAckTimer,   Step::kRetryLimit,
                                    Step::kExplicitEpr};
  const InputConnection& cos = *config_.profile.input_connection;
  const auto applies = [&](Step s) {
    switch (s) {
      case Step::kSetCosPath:
        return !cos.produced_path.empty();
      case Step::kCosInhibit:
        return cos.kind == InputKind::kChangeOfState && cos.inhibit.has_value();
      case Step::kAckTimer:
      case Step::kRetryLimit:
        return cos.acknowledged && !cos.strobed();
      default:
        return true;
    }
  };
  const auto* at = std::find(std::begin(kOrder), std::end(kOrder), step);
  if (at == std::end(kOrder)) return Step::kExplicitEpr;  // not a step of the input connection
  for (++at; at != std::end(kOrder); ++at) {
    if (applies(*at)) return *at;
  }
  return Step::kExplicitEpr;
}

Node::Step Node::after_allocate_cos(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    input_.allocation().allocated = true;
    return cos_step_after(Step::kAllocateCos);
  }
  const std::string_view kind = to_string(config_.profile.input_connection->kind);
  return io_allocate_refused(
      r, now, fmt::format("Allocate of the {} connection (choice 0x{:02X})", kind, input_.choice()),
      fmt::format("; the node's connection = \"{}\" needs it", kind), input_.allocation(),
      Step::kReleaseCosForAllocate);
}

// The answers to the change-of-state connection's set-up: what the device
// refuses but can do without is logged and the set-up goes on; a produced
// size other than the configuration's is a fault.
Node::Step Node::after_cos_step(const ExplicitResult& r, TimePoint now) {
  const Step step = last_step_;
  const cip::AttributeRef target = target_of(step);
  const InputConnection& cos = *config_.profile.input_connection;
  switch (step) {
    case Step::kSetCosPath:
      if (!r.ok()) {
        input_.set_path_refusal(fmt::format("; Set of {} to {} refused: {}", target.name,
                                            hex(Bytes(cos.produced_path)), status_text(r)));
        log_.info("{}: the size tells whether the device's own path serves",
                  input_.path_refusal().substr(2));
      }
      break;
    case Step::kCosInhibit:
      if (!r.ok()) {
        log_.warn("the device refused {} = {} ms ({}): it keeps its own", target.name,
                  to_ms(*cos.inhibit), status_text(r));
      }
      break;
    case Step::kCosSize: {
      const auto size = r.ok() ? read_uint(r.data.view()) : std::nullopt;
      if (!r.ok()) {
        log_.info("{} not read ({}): every message's size is checked", target.name, status_text(r));
      } else if (!size || *size != cos.produced_size) {
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("{} is {}, the configuration expects {} bytes{}", target.name,
                                size ? fmt::format("{} bytes", *size) : hex(r.data.view()),
                                cos.produced_size, input_.path_refusal()),
                    now);
        return Step::kNone;
      }
      break;
    }
    case Step::kAckTimer:
    case Step::kRetryLimit: {
      const auto v = r.ok() ? read_uint(r.data.view()) : std::nullopt;
      if (!v) {
        input_.note_ack_handler_unread();
        log_.info("{} not read ({}): taking the default, {}", target.name,
                  r.ok() ? hex(r.data.view()) : status_text(r),
                  step == Step::kAckTimer ? "20 ms" : "1 retry");
      } else if (step == Step::kAckTimer) {
        input_.set_ack_timer(milliseconds(*v));
      } else {
        input_.set_retry_limit(static_cast<std::uint8_t>(std::min<std::uint32_t>(*v, 255)));
      }
      break;
    }
    case Step::kCosEpr: {
      // As the poll's: the value the device returned is the one it uses.
      input_.set_epr(returned_epr(r, input_.epr_asked()));
      break;
    }
    default:
      break;
  }
  return cos_step_after(step);
}

}  // namespace dnbridge::devicenet
