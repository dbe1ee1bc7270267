// Node: its start-up as one ordered table of steps (kStartup below), and the
// handlers that check what the device answers.
//
// The rule the table follows: read what the device has before writing; write
// only what differs, and read it back; where the device refuses but what it
// has serves the configuration, go on; where it cannot serve, stop with a
// reason naming the object, the attribute, the CIP status and what was
// expected. The explicit connection comes first and alone: a device may
// refuse its Configuration object while a poll connection exists (CDN127
// manual, Configuration object NOTE 1), so the poll connection is allocated
// only once the configuration is in place.
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/cip/data_types.hpp"
#include "bridge/cip/identity_health.hpp"
#include "bridge/devicenet/master/node.hpp"
#include "bridge/devicenet/master/node_internal.hpp"

namespace dnbridge::devicenet {

using namespace node_detail;

namespace {

namespace conn = cip::connection;
namespace ack = cip::acknowledge_handler;
namespace ident = cip::identity;

// Targets a row cannot name itself: they come from the profile.
constexpr cip::AttributeRef kProfileSetting{0, 0, 0, "(the profile's setting in hand)"};
constexpr cip::AttributeRef kProfileSizeFallback{0, 0, 0, "(the profile's size fallback)"};
constexpr cip::AttributeRef kProfileCheck{0, 0, 0, "(the profile's check in hand)"};
constexpr cip::AttributeRef kDeviceNetObject{cip::devicenet_object::kClass, 1, 0, "DeviceNet"};

}  // namespace

// The start-up, in order. A step's request is built from its row; a good
// answer goes to `next` unless the handler chooses; a refusal (CIP error
// reply) goes where `on_refusal` says; no answer is retried twice on the
// explicit connection and then taken for a lost node (Allocate of the
// explicit connection: the node is absent, retried with back-off).
// clang-format off
const Node::StepRow Node::kStartup[] = {
  // step                        phase                          verb               target                                    choice                on refusal                     next                         handler
  {Step::kAllocateExplicit, NodeState::kAbsent,       Verb::kAllocate, kDeviceNetObject,                      allocation::kExplicit, OnRefusal::kHandler,     Step::kAllocationInfo,  &Node::after_allocate_explicit},
  {Step::kReleaseStale,     NodeState::kAbsent,       Verb::kRelease,  kDeviceNetObject,                      allocation::kExplicit, OnRefusal::kGoOn,        Step::kAllocateExplicit, nullptr},
  {Step::kAllocationInfo,   NodeState::kIdentifying,  Verb::kGet,      cip::devicenet_object::kAllocationInformation, 0,             OnRefusal::kGoOn,        Step::kVendor,          &Node::after_allocation_info},
  {Step::kReleaseStalePoll, NodeState::kIdentifying,  Verb::kRelease,  kDeviceNetObject,                      allocation::kPoll,     OnRefusal::kGoOn,        Step::kVendor,          nullptr},
  {Step::kVendor,           NodeState::kIdentifying,  Verb::kGet,      ident::kVendorId,                      0,                     OnRefusal::kWrongDevice, Step::kProductType,     &Node::after_identity_match},
  {Step::kProductType,      NodeState::kIdentifying,  Verb::kGet,      ident::kProductType,                   0,                     OnRefusal::kWrongDevice, Step::kProductCode,     &Node::after_identity_match},
  {Step::kProductCode,      NodeState::kIdentifying,  Verb::kGet,      ident::kProductCode,                   0,                     OnRefusal::kWrongDevice, Step::kRevision,        &Node::after_identity_match},
  {Step::kRevision,         NodeState::kIdentifying,  Verb::kGet,      ident::kRevision,                      0,                     OnRefusal::kGoOn,        Step::kSerial,          &Node::after_revision},
  {Step::kSerial,           NodeState::kIdentifying,  Verb::kGet,      ident::kSerialNumber,                  0,                     OnRefusal::kHandler,     Step::kName,            &Node::after_serial},
  {Step::kName,             NodeState::kIdentifying,  Verb::kGet,      ident::kProductName,                   0,                     OnRefusal::kGoOn,        Step::kIdentityStatus,  &Node::after_name},
  {Step::kIdentityStatus,   NodeState::kIdentifying,  Verb::kGet,      ident::kStatus,                        0,                     OnRefusal::kHandler,     Step::kIdentityState,   &Node::after_identity_status},
  {Step::kIdentityState,    NodeState::kIdentifying,  Verb::kGet,      ident::kState,                         0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_identity_state},
  {Step::kReadSetting,      NodeState::kConfiguring,  Verb::kGet,      kProfileSetting,                       0,                     OnRefusal::kFault,       Step::kNone,            &Node::after_read_setting},
  {Step::kWriteSetting,     NodeState::kConfiguring,  Verb::kSet,      kProfileSetting,                       0,                     OnRefusal::kHandler,     Step::kVerifySetting,   &Node::after_write_setting},
  {Step::kReleasePollForSetting, NodeState::kConfiguring, Verb::kRelease, kDeviceNetObject,                   allocation::kPoll,     OnRefusal::kHandler,     Step::kWriteSetting,    &Node::after_release_for_setting},
  {Step::kVerifySetting,    NodeState::kConfiguring,  Verb::kGet,      kProfileSetting,                       0,                     OnRefusal::kFault,       Step::kNone,            &Node::after_verify_setting},
  {Step::kCheckAttribute,   NodeState::kConfiguring,  Verb::kGet,      kProfileCheck,                         0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_check},
  {Step::kAllocatePoll,     NodeState::kConfiguring,  Verb::kAllocate, kDeviceNetObject,                      allocation::kPoll,     OnRefusal::kHandler,     Step::kGetProducedPath, &Node::after_allocate_poll},
  {Step::kReleasePollForAllocate, NodeState::kConfiguring, Verb::kRelease, kDeviceNetObject,                  allocation::kPoll,     OnRefusal::kGoOn,        Step::kAllocatePoll,    nullptr},
  {Step::kGetProducedPath,  NodeState::kConfiguring,  Verb::kGet,      conn::kPollProducedPath,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_get_path},
  {Step::kSetProducedPath,  NodeState::kConfiguring,  Verb::kSet,      conn::kPollProducedPath,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_set_path},
  {Step::kGetConsumedPath,  NodeState::kConfiguring,  Verb::kGet,      conn::kPollConsumedPath,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_get_path},
  {Step::kSetConsumedPath,  NodeState::kConfiguring,  Verb::kSet,      conn::kPollConsumedPath,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_set_path},
  {Step::kProducedSize,     NodeState::kVerifying,    Verb::kGet,      conn::kPollProducedSize,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_size},
  {Step::kConsumedSize,     NodeState::kVerifying,    Verb::kGet,      conn::kPollConsumedSize,               0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_size},
  {Step::kFallbackProducedSize, NodeState::kVerifying, Verb::kGet,     kProfileSizeFallback,                  0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_size},
  {Step::kFallbackConsumedSize, NodeState::kVerifying, Verb::kGet,     kProfileSizeFallback,                  0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_size},
  {Step::kExplicitEpr,      NodeState::kVerifying,    Verb::kSet,      conn::kExplicitExpectedPacketRate,     0,                     OnRefusal::kFault,       Step::kPollEpr,         &Node::after_epr},
  {Step::kPollEpr,          NodeState::kVerifying,    Verb::kSet,      conn::kPollExpectedPacketRate,         0,                     OnRefusal::kFault,       Step::kNone,            &Node::after_epr},
  // The choice of kAllocateCos is the profile's (cos_choice()).
  {Step::kAllocateCos,      NodeState::kVerifying,    Verb::kAllocate, kDeviceNetObject,                      0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_allocate_cos},
  {Step::kReleaseCosForAllocate, NodeState::kVerifying, Verb::kRelease, kDeviceNetObject,              0,                     OnRefusal::kGoOn,        Step::kAllocateCos,     nullptr},
  {Step::kSetCosPath,       NodeState::kVerifying,    Verb::kSet,      conn::kCosProducedPath,                0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_cos_step},
  {Step::kCosInhibit,       NodeState::kVerifying,    Verb::kSet,      conn::kCosInhibitTime,                 0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_cos_step},
  {Step::kCosSize,          NodeState::kVerifying,    Verb::kGet,      conn::kCosProducedSize,                0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_cos_step},
  {Step::kAckTimer,         NodeState::kVerifying,    Verb::kGet,      ack::kAckTimer,                        0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_cos_step},
  {Step::kRetryLimit,       NodeState::kVerifying,    Verb::kGet,      ack::kRetryLimit,                      0,                     OnRefusal::kHandler,     Step::kNone,            &Node::after_cos_step},
  {Step::kCosEpr,           NodeState::kVerifying,    Verb::kSet,      conn::kCosExpectedPacketRate,          0,                     OnRefusal::kFault,       Step::kNone,            &Node::after_cos_step},
};
// clang-format on

const Node::StepRow& Node::row(Step step) {
  for (const auto& r : kStartup) {
    if (r.step == step) return r;
  }
  // Outside start-up: the keep-alive and the releases have no row.
  static constexpr StepRow kNoRow{Step::kNone, NodeState::kAbsent, Verb::kGet,  {},
                                  0,           OnRefusal::kGoOn,   Step::kNone, nullptr};
  return kNoRow;
}

namespace {

std::string_view phase_reason(NodeState phase) {
  switch (phase) {
    case NodeState::kIdentifying:
      return "allocated: checking identity";
    case NodeState::kConfiguring:
      return "identity verified";
    case NodeState::kVerifying:
      return "configured: checking the poll connection's sizes";
    default:
      return "";
  }
}

std::string_view verb_name(std::uint8_t service) {
  switch (static_cast<cip::Service>(service)) {
    case cip::Service::kGetAttributeSingle:
      return "Get";
    case cip::Service::kSetAttributeSingle:
      return "Set";
    case cip::Service::kAllocateMasterSlave:
      return "Allocate";
    case cip::Service::kReleaseMasterSlave:
      return "Release";
    default:
      return "request";
  }
}

// The EPR a Set of it returned (the device rounds it to its timer
// resolution), or the one asked when it returned none.
Duration returned_epr(const ExplicitResult& r, Duration asked) {
  const auto actual = read_uint(r.data.view());
  return actual && *actual > 0 ? milliseconds(*actual) : asked;
}

std::array<std::uint8_t, 2> uint_le(std::uint16_t v) {
  return {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)};
}

}  // namespace

// --- running steps -----------------------------------------------------------

void Node::issue(Step step, const RequestMessage& request, bool unconnected, TimePoint now,
                 std::optional<Duration> timeout) {
  // Kept so that a request lost on the bus can be sent again as it was.
  last_step_ = step;
  last_request_ = request;
  last_request_data_.assign(request.data);
  last_request_.data = last_request_data_.view();
  last_unconnected_ = unconnected;
  last_timeout_ = timeout;
  step_ = step;
  auto submitted = client_.submit(kInternalTag | static_cast<std::uint32_t>(step), request,
                                  unconnected, now, timeout);
  if (!submitted) {
    // Only a request larger than the message buffer can fail here: the
    // internal requests are small and external ones leave room in the queue.
    step_ = Step::kNone;
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("cannot send a life-cycle request: {}", submitted.error().message()),
                now);
  }
}

void Node::resend_step(TimePoint now) {
  ++counters_.explicit_retries;
  const InlineBytes<64> data = last_request_data_;
  RequestMessage request = last_request_;
  request.data = data.view();
  issue(last_step_, request, last_unconnected_, now, last_timeout_);
}

void Node::get(Step step, const cip::AttributeRef& target, TimePoint now) {
  RequestMessage r;
  r.service = cip::code(cip::Service::kGetAttributeSingle);
  r.class_id = target.class_id;
  r.instance_id = target.instance_id;
  r.attribute = target.attribute;
  issue(step, r, false, now);
}

std::uint8_t Node::held_connections() const {
  // A poll connection asked for but not yet confirmed may be the device's
  // already: released with the rest (a device without it refuses that
  // Release with 0x0B, and the explicit connection is released alone).
  // The same holds of a change-of-state connection.
  return static_cast<std::uint8_t>((connected_ ? allocation::kExplicit : 0) |
                                   (poll_allocated_ || poll_requested_ ? allocation::kPoll : 0) |
                                   (cos_allocated_ || cos_requested_ ? cos_connection_bits() : 0));
}

std::uint8_t Node::cos_connection_bits() const {
  return static_cast<std::uint8_t>(cos_choice() & ~allocation::kAckSuppression);
}

std::uint8_t Node::cos_choice() const {
  const auto& in = config_.profile.input_connection;
  if (!in) return 0;
  switch (in->kind) {
    case InputKind::kBitStrobe:
      return allocation::kBitStrobe;
    case InputKind::kCyclic:
      return static_cast<std::uint8_t>(allocation::kCyclic |
                                       (in->acknowledged ? 0 : allocation::kAckSuppression));
    case InputKind::kChangeOfState:
      break;
  }
  return static_cast<std::uint8_t>(allocation::kChangeOfState |
                                   (in->acknowledged ? 0 : allocation::kAckSuppression));
}

void Node::release(Step step, std::uint8_t choice, TimePoint now) {
  releases_left_ = 0;
  const std::array<std::uint8_t, 1> data{choice};
  RequestMessage r;
  r.service = cip::code(cip::Service::kReleaseMasterSlave);
  r.class_id = kDeviceNetObject.class_id;
  r.instance_id = 1;
  r.data = Bytes(data);
  issue(step, r, true, now);
}

void Node::release_after_loss(TimePoint now) {
  if (state_ == NodeState::kStopped) return;
  shutting_down_ = true;
  reports_data_ = false;
  // Its idle poll on retiring may have been lost with the bus, and the device
  // may have kept the connection through a short loss: idle first.
  idle_poll_before_release(now);
  release(
      Step::kReleaseShutdown,
      static_cast<std::uint8_t>(allocation::kExplicit | allocation::kPoll | cos_connection_bits()),
      now);
}

void Node::attempt_allocate(TimePoint now) {
  retry_at_ = kNever;
  step_timeouts_ = 0;
  poll_release_tried_ = false;
  cos_release_tried_ = false;
  stray_poll_responses_ = 0;  // what did not come by now is not coming
  ack_handler_unread_ = false;
  setting_retried_ = false;
  // What an attempt learns is its own: paths and refusals from an earlier one
  // would otherwise pile up in the reasons.
  path_refusal_.clear();
  produced_path_in_force_.clear();
  consumed_path_in_force_.clear();
  cos_path_refusal_.clear();
  cos_asked_ = CosSettings{};
  if (const auto& in = config_.profile.input_connection) {
    cos_asked_.expected_packet_rate = input_epr_asked();
    // Nothing acknowledges a bit-strobe response.
    cos_asked_.ack_suppressed = !in->acknowledged || in->strobed();
  }
  ++counters_.allocate_attempts;
  run(Step::kAllocateExplicit, now);
}

void Node::run(Step step, TimePoint now) {
  const StepRow& r = row(step);
  if (r.phase != NodeState::kAbsent && r.phase != state_) {
    set_state(r.phase, std::string(phase_reason(r.phase)), now);
  }
  if (step == Step::kAllocatePoll) poll_requested_ = true;
  if (step == Step::kAllocateCos) cos_requested_ = true;
  if (step == Step::kCosEpr) {
    // Setting EPR starts production: a message may come before the answer.
    cos_.emplace(config_.mac, cos_asked_, now);
    cos_reassembler_.reset();
  }
  switch (r.verb) {
    case Verb::kAllocate: {
      const std::uint8_t choice = step == Step::kAllocateCos ? cos_choice() : r.choice;
      const std::array<std::uint8_t, 2> data{choice, port_.master_mac.value()};
      RequestMessage m;
      m.service = cip::code(cip::Service::kAllocateMasterSlave);
      m.class_id = kDeviceNetObject.class_id;
      m.instance_id = 1;
      m.data = Bytes(data);
      issue(step, m, true, now);
      return;
    }
    case Verb::kRelease: {
      const std::uint8_t choice = step == Step::kReleaseStalePoll        ? stale_choice_
                                  : step == Step::kReleaseCosForAllocate ? cos_connection_bits()
                                                                         : r.choice;
      // A poll connection released during the start-up may be one left from
      // before (a restart, or a bus lost and back, within the device's own
      // timeout), still carrying the outputs last commanded: idle first.
      if ((choice & allocation::kPoll) != 0) idle_poll_before_release(now);
      release(step, choice, now);
      return;
    }
    case Verb::kGet:
      get(step, target_of(step), now);
      return;
    case Verb::kSet: {
      const cip::AttributeRef target = target_of(step);
      InlineBytes<16> value;
      std::optional<Duration> timeout;
      switch (step) {
        case Step::kWriteSetting:
          value.assign(Bytes(config_.profile.settings[setting_index_].value));
          break;
        case Step::kSetProducedPath:
        case Step::kSetConsumedPath:
          value.assign(wanted_path(step == Step::kSetProducedPath));
          break;
        case Step::kExplicitEpr:
          value.assign(Bytes(uint_le(to_ms(config_.explicit_packet_rate))));
          break;
        case Step::kPollEpr:
          // Setting EPR establishes the poll connection and starts the
          // device's 4 x EPR watchdog, so the first poll follows at once. A
          // lost answer is retried after 2 x EPR, while the connection lives.
          value.assign(Bytes(uint_le(to_ms(config_.expected_packet_rate))));
          timeout = std::min(client_.response_timeout(), 2 * config_.expected_packet_rate);
          break;
        case Step::kSetCosPath:
          value.assign(Bytes(config_.profile.input_connection->produced_path));
          break;
        case Step::kCosInhibit:
          value.assign(Bytes(uint_le(to_ms(*config_.profile.input_connection->inhibit))));
          break;
        case Step::kCosEpr:
          // Right after the poll connection's start, bounded as its Set was.
          value.assign(Bytes(uint_le(to_ms(input_epr_asked()))));
          timeout = std::min(client_.response_timeout(), 2 * poll_epr_);
          break;
        default:
          break;
      }
      RequestMessage m;
      m.service = cip::code(cip::Service::kSetAttributeSingle);
      m.class_id = target.class_id;
      m.instance_id = target.instance_id;
      m.attribute = target.attribute;
      m.data = value.view();
      issue(step, m, false, now, timeout);
      return;
    }
  }
}

void Node::advance(Step next, TimePoint now) {
  if (next == Step::kNone) return;
  if (next == Step::kOnline) {
    go_online(now);
    return;
  }
  run(next, now);
}

cip::AttributeRef Node::target_of(Step step) const {
  const StepRow& r = row(step);
  // The rows name Connection 4; a bit-strobe connection is instance 3.
  if (config_.profile.input_connection && config_.profile.input_connection->strobed()) {
    switch (step) {
      case Step::kSetCosPath:
        return conn::kStrobeProducedPath;
      case Step::kCosSize:
        return conn::kStrobeProducedSize;
      case Step::kCosEpr:
        return conn::kStrobeExpectedPacketRate;
      default:
        break;
    }
  }
  // The two profile targets share class, instance and attribute 0: their
  // names tell them apart.
  if (r.target.name == kProfileSetting.name) {
    const auto& s = config_.profile.settings[setting_index_];
    return {s.class_id, s.instance_id, s.attribute, s.name};
  }
  if (r.target.name == kProfileCheck.name) {
    const auto& c = config_.profile.checks[check_index_];
    return {c.class_id, c.instance_id, c.attribute, c.name};
  }
  if (r.target.name == kProfileSizeFallback.name) {
    const auto& fb = config_.profile.size_fallback;
    return {fb.class_id, fb.instance_id,
            step == Step::kFallbackProducedSize ? fb.produced_attribute : fb.consumed_attribute,
            fb.object_name};
  }
  return r.target;
}

// --- answers -------------------------------------------------------------------

void Node::on_explicit_result(std::uint32_t tag, const ExplicitResult& result, TimePoint now) {
  if (result.ok() || result.error == Errc::kDeviceError) last_explicit_answer_ = now;
  if ((tag & kInternalTag) == 0) {
    observer_.on_explicit_result(tag, config_.mac, result, now);
    return;
  }
  const auto step = static_cast<Step>(tag & 0xFF);
  if (step != step_) return;  // a cancelled step
  step_ = Step::kNone;
  on_step_result(step, result, now);
}

void Node::on_step_result(Step step, const ExplicitResult& r, TimePoint now) {
  if (r.error == Errc::kStopped) return;  // cancelled by shutdown or halt
  // What a Release after a loss or a fault answers (a refusal of what the
  // device no longer holds, or nothing from a device gone) is not news: the
  // last error stays the one that made the node leave.
  const bool releasing = step == Step::kReleaseFault || step == Step::kReleaseShutdown;
  if (!releasing) {
    if (r.error == Errc::kDeviceError) record_device_error(r, now);
    if (r.error == Errc::kTimeout) record(NodeError::Kind::kExplicitTimeout, now);
    if (r.error == Errc::kAborted) record(NodeError::Kind::kExplicitAborted, now);
    if (r.error == Errc::kMalformed) record(NodeError::Kind::kExplicitMalformed, now);
  }

  switch (step) {
    case Step::kKeepAlive:
      on_keepalive_result(r, now);
      return;
    case Step::kReleaseFault:
    case Step::kReleaseShutdown:
      // Released with a connection the device did not have: refused whole
      // (0x0B). Then one connection at a time, whatever each answer: the
      // I/O connections first, the explicit connection last.
      if (!last_request_data_.empty()) {
        const std::uint8_t asked = last_request_data_.view()[0];
        std::uint8_t left = static_cast<std::uint8_t>(releases_left_ & ~asked);
        if (releases_left_ == 0 && r.error == Errc::kDeviceError &&
            r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode &&
            (asked & (asked - 1)) != 0) {
          left = asked;
        }
        if (left != 0) {
          // Its lowest bit but the explicit connection's, while there is one.
          const std::uint8_t io = left & static_cast<std::uint8_t>(~allocation::kExplicit);
          const auto next = static_cast<std::uint8_t>(io != 0 ? io & -io : left);
          release(step, next, now);
          releases_left_ = left;
          return;
        }
      }
      connected_ = poll_allocated_ = poll_requested_ = cos_allocated_ = cos_requested_ = false;
      cos_.reset();
      // Whatever the answer, a faulted node is left alone until the re-check.
      if (step == Step::kReleaseShutdown) {
        set_state(NodeState::kStopped, "released by " + shutdown_why_, now);
      }
      return;
    case Step::kAllocateExplicit:
      // No answer here is an absent node: the handler retries with back-off.
      advance((this->*row(step).handler)(r, now), now);
      return;
    case Step::kReleaseStale:
      // Whatever the answer, allocate again after a back-off: a device that
      // keeps saying "already allocated" is not asked more often than that.
      retry_at_ = now + next_backoff();
      return;
    default:
      break;
  }

  const StepRow& rule = row(step);
  if (r.error && r.error != Errc::kDeviceError) {
    // A lost frame is retried; a node silent on its explicit connection is
    // gone.
    if (++step_timeouts_ <= kStepTimeoutRetries) {
      resend_step(now);
      return;
    }
    lose(fmt::format("no answer to {} {} ({})", verb_name(last_request_.service),
                     target_of(step).name, status_text(r)),
         now);
    return;
  }
  step_timeouts_ = 0;  // answered, even if with an error

  if (r.ok()) {
    advance(rule.handler ? (this->*rule.handler)(r, now) : rule.next, now);
    return;
  }
  const cip::AttributeRef target = target_of(step);
  switch (rule.on_refusal) {
    case OnRefusal::kFault:
      enter_fault(NodeState::kConfigurationFault,
                  fmt::format("device refused {} {}: {}{}", verb_name(last_request_.service),
                              target.name, status_text(r), setting_expectation(step)),
                  now);
      return;
    case OnRefusal::kWrongDevice:
      enter_fault(NodeState::kWrongDevice,
                  fmt::format("{} unreadable: {}", target.name, status_text(r)), now);
      return;
    case OnRefusal::kGoOn:
      log_.debug("{} {} refused ({}): going on", verb_name(last_request_.service), target.name,
                 status_text(r));
      advance(rule.next, now);
      return;
    case OnRefusal::kHandler:
      advance((this->*rule.handler)(r, now), now);
      return;
  }
}

// --- allocation ----------------------------------------------------------------

Node::Step Node::after_allocate_explicit(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    // The device is ours from here on: a fault below releases it.
    connected_ = true;
    auto format = decode_allocate_response_data(r.data.view());
    if (!format) {
      enter_fault(
          NodeState::kConfigurationFault,
          fmt::format("Allocate response has an unsupported body format ({})", hex(r.data.view())),
          now);
      return Step::kNone;
    }
    client_.set_body_format(*format);
    return Step::kAllocationInfo;
  }
  if (r.error == Errc::kDeviceError) {
    if (r.general_status == cip::GeneralStatus::kObjectStateConflict &&
        r.additional_status == 0x01) {
      enter_fault(NodeState::kOwnedByOtherMaster,
                  "Allocate refused: owned by another master (0x0C/0x01)", now);
      return Step::kNone;
    }
    if (r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode) {
      // Still allocated to this master from before (a restart of the
      // master): release and allocate afresh, to learn its body format.
      return Step::kReleaseStale;
    }
    enter_fault(NodeState::kConfigurationFault, fmt::format("Allocate refused: {}", status_text(r)),
                now);
    return Step::kNone;
  }
  // No answer: the node is absent. Retry with back-off, forever.
  if (state_ != NodeState::kAbsent) {
    set_state(NodeState::kAbsent, fmt::format("no answer to Allocate ({})", status_text(r)), now);
  }
  retry_at_ = now + next_backoff();
  return Step::kNone;
}

Node::Step Node::after_allocation_info(const ExplicitResult& r, TimePoint) {
  // I/O connections left from before (this master's, restarted) are
  // released: they are made afresh once the configuration is in place.
  constexpr std::uint8_t kIo = allocation::kPoll | allocation::kBitStrobe |
                               allocation::kMulticastPoll | allocation::kChangeOfState |
                               allocation::kCyclic;
  if (r.ok() && !r.data.empty() && (r.data[0] & kIo) != 0) {
    stale_choice_ = static_cast<std::uint8_t>(r.data[0] & kIo);
    log_.info("I/O connections are still allocated from before (0x{:02X}): releasing them",
              stale_choice_);
    return Step::kReleaseStalePoll;
  }
  return Step::kVendor;
}

Node::Step Node::after_allocate_poll(const ExplicitResult& r, TimePoint now) {
  if (r.ok()) {
    poll_allocated_ = true;
    if (!config_.profile.produced_path.empty()) return Step::kGetProducedPath;
    if (!config_.profile.consumed_path.empty()) return Step::kGetConsumedPath;
    return begin_verify(now);
  }
  return io_allocate_refused(r, now, "Allocate of the poll connection", "", poll_release_tried_,
                             poll_requested_, Step::kReleasePollForAllocate);
}

Node::Step Node::io_allocate_refused(const ExplicitResult& r, TimePoint now, std::string_view what,
                                     std::string_view needed_by, bool& release_tried,
                                     bool& requested, Step release_step) {
  // Held already (its answer to an Allocate lost on the bus, or left from
  // before): released, then allocated once more.
  if (r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode && !release_tried) {
    release_tried = true;
    return release_step;
  }
  requested = false;  // refused: the device did not give it
  if (r.general_status == cip::GeneralStatus::kObjectStateConflict && r.additional_status == 0x01) {
    enter_fault(NodeState::kOwnedByOtherMaster,
                fmt::format("{} refused: owned by another master (0x0C/0x01)", what), now);
    return Step::kNone;
  }
  enter_fault(NodeState::kConfigurationFault,
              fmt::format("{} refused: {}{}", what, status_text(r), needed_by), now);
  return Step::kNone;
}

// --- identity ------------------------------------------------------------------

// Vendor, product type and product code: the identity the scan list expects.
Node::Step Node::after_identity_match(const ExplicitResult& r, TimePoint now) {
  const auto value = read_uint(r.data.view());
  if (!value) {
    enter_fault(
        NodeState::kWrongDevice,
        fmt::format("{} unreadable: bad size {}", target_of(last_step_).name, hex(r.data.view())),
        now);
    return Step::kNone;
  }
  const auto v = static_cast<std::uint16_t>(*value);
  if (last_step_ == Step::kVendor) {
    identity_.vendor_id = v;
    return Step::kProductType;
  }
  if (last_step_ == Step::kProductType) {
    identity_.product_type = v;
    return Step::kProductCode;
  }
  identity_.product_code = v;
  const auto& want = config_.profile.identity;
  if (identity_.vendor_id != want.vendor_id || identity_.product_type != want.product_type ||
      identity_.product_code != want.product_code) {
    enter_fault(NodeState::kWrongDevice,
                fmt::format("expected vendor {} product type {} product code {}, found "
                            "vendor {} product type {} product code {}",
                            want.vendor_id, want.product_type, want.product_code,
                            identity_.vendor_id, identity_.product_type, identity_.product_code),
                now);
    return Step::kNone;
  }
  return Step::kRevision;
}

// Revision, name and status are information: a device that refuses them is
// still the expected device.
// (A refused one is cleared: it may be another device than last time.)
Node::Step Node::after_revision(const ExplicitResult& r, TimePoint) {
  const bool ok = r.ok() && r.data.size() >= 2;
  identity_.major_revision = ok ? r.data[0] : 0;
  identity_.minor_revision = ok ? r.data[1] : 0;
  return Step::kSerial;
}

Node::Step Node::after_serial(const ExplicitResult& r, TimePoint now) {
  // The CDN127 manual types the serial number UINT, the ODVA Identity object
  // UDINT: either is taken.
  const auto serial = r.ok() ? read_uint(r.data.view()) : std::nullopt;
  if (config_.serial_number) {
    if (!serial) {
      enter_fault(NodeState::kWrongDevice,
                  fmt::format("cannot check the configured serial number 0x{:08X}: {} {}",
                              *config_.serial_number, ident::kSerialNumber.name,
                              r.ok() ? "bad size " + hex(r.data.view()) : status_text(r)),
                  now);
      return Step::kNone;
    }
    if (*serial != *config_.serial_number) {
      enter_fault(NodeState::kWrongDevice,
                  fmt::format("serial number 0x{:08X}, the configuration expects 0x{:08X} "
                              "(a swapped module, or a misset MAC switch?)",
                              *serial, *config_.serial_number),
                  now);
      return Step::kNone;
    }
  }
  identity_.serial_number = serial.value_or(0);
  if (serial) {
    if (first_serial_ && *first_serial_ != *serial) {
      log_.warn("serial number changed from 0x{:08X} to 0x{:08X}: another device at this MAC",
                *first_serial_, *serial);
    }
    first_serial_ = *serial;
  }
  return Step::kName;
}

Node::Step Node::after_name(const ExplicitResult& r, TimePoint) {
  identity_.product_name.clear();
  if (!r.ok()) return Step::kIdentityStatus;
  if (auto name = cip::decode_short_string(r.data.view()); name) {
    identity_.product_name = std::string(*name);
  }
  return Step::kIdentityStatus;
}

Node::Step Node::after_identity_status(const ExplicitResult& r, TimePoint) {
  identity_.status.reset();
  if (r.ok() && r.data.size() == 2)
    identity_.status = static_cast<std::uint16_t>(*read_uint(r.data.view()));
  if (!r.ok()) log_.info("{} not readable ({})", ident::kStatus.name, status_text(r));
  note_minor_faults();
  return Step::kIdentityState;
}

Node::Step Node::after_identity_state(const ExplicitResult& r, TimePoint now) {
  // Optional in the Identity object: a device without it (0x14 attribute
  // not supported, or 0x08 service not supported) is not at fault; its
  // state is unknown and the keep-alive reads Identity.Status instead.
  identity_.state.reset();
  identity_state_supported_ = r.ok();
  if (r.ok() && r.data.size() == 1) {
    identity_.state = r.data[0];
    if (device_state_ != r.data[0]) {
      device_state_ = r.data[0];
      observer_.on_device_state(config_.mac, r.data[0], now);
    }
  } else if (!r.ok()) {
    log_.info("{} not supported ({}): state unknown", ident::kState.name, status_text(r));
  }
  observer_.on_node_identity(config_.mac, identity_, now);
  if (!check_health(now)) return Step::kNone;
  setting_index_ = 0;
  settings_in_force_.assign(config_.profile.settings.size(), {});
  return first_setting_step();
}

// --- configuration ---------------------------------------------------------------

std::string Node::setting_expectation(Step step) const {
  if (step != Step::kReadSetting && step != Step::kVerifySetting) return {};
  const auto& s = config_.profile.settings[setting_index_];
  if (s.keep_device_value) {
    return fmt::format("; the device's own value is kept: expected {} byte(s), 0..{}",
                       s.value.size(), s.device_value_max);
  }
  return fmt::format("; the configuration needs {}", hex(Bytes(s.value)));
}

Node::Step Node::first_setting_step() {
  setting_retried_ = false;
  if (setting_index_ < config_.profile.settings.size()) return Step::kReadSetting;
  check_index_ = 0;
  return next_check_step();
}

Node::Step Node::next_check_step() {
  return check_index_ < config_.profile.checks.size() ? Step::kCheckAttribute : Step::kAllocatePoll;
}

Node::Step Node::after_check(const ExplicitResult& r, TimePoint now) {
  const auto& c = config_.profile.checks[check_index_];
  ++check_index_;
  if (!r.ok()) {
    // Not offered (service, attribute or object not there): not compared.
    // Any other refusal leaves the device unchecked: a fault, not a guess.
    using cip::GeneralStatus;
    const auto g = r.general_status;
    if (g == GeneralStatus::kServiceNotSupported || g == GeneralStatus::kAttributeNotSupported ||
        g == GeneralStatus::kObjectDoesNotExist || g == GeneralStatus::kPathDestinationUnknown) {
      log_.info("{} not offered ({}): not compared", c.name, status_text(r));
      return next_check_step();
    }
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} could not be read ({}): the device is not checked against what "
                            "the configuration expects",
                            c.name, status_text(r)),
                now);
    return Step::kNone;
  }
  const auto differences =
      c.verifier ? c.verifier->differences(r.data.view()) : std::vector<std::string>{};
  if (!differences.empty()) {
    std::string text;
    for (const auto& d : differences) text += (text.empty() ? "" : "; ") + d;
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} differs from what the configuration expects: {}", c.name, text),
                now);
    return Step::kNone;
  }
  return next_check_step();
}

Node::Step Node::after_read_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  const bool equal =
      std::equal(r.data.view().begin(), r.data.view().end(), s.value.begin(), s.value.end());
  if (s.keep_device_value) {
    const auto v = read_uint(r.data.view());
    if (r.data.size() != s.value.size() || !v || *v > s.device_value_max) {
      enter_fault(NodeState::kConfigurationFault,
                  fmt::format("{} reads {}: expected {} byte(s), 0..{} (the device's own value "
                              "is kept, but this one is not one the profile knows)",
                              s.name, hex(r.data.view()), s.value.size(), s.device_value_max),
                  now);
      return Step::kNone;
    }
    log_.info("{} is {}: the device's own, kept", s.name, hex(r.data.view()));
  }
  if (equal || s.keep_device_value) {
    settings_in_force_[setting_index_].assign(r.data.view().begin(), r.data.view().end());
    ++setting_index_;
    return first_setting_step();
  }
  log_.info("{} is {}, setting {}", s.name, hex(r.data.view()), hex(Bytes(s.value)));
  setting_found_.assign(r.data.view());
  return Step::kWriteSetting;
}

Node::Step Node::after_write_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  if (r.ok()) {
    ++counters_.settings_written;
    return Step::kVerifySetting;
  }
  // A device that takes no configuration while a poll connection exists
  // (CDN127 manual, Configuration object NOTE 1): release it, try once more.
  if (r.general_status == cip::GeneralStatus::kObjectStateConflict && !setting_retried_) {
    setting_retried_ = true;
    log_.info("device refused {} = {} ({}): releasing the poll connection and trying again", s.name,
              hex(Bytes(s.value)), status_text(r));
    return Step::kReleasePollForSetting;
  }
  enter_fault(NodeState::kConfigurationFault,
              fmt::format("device refused Set {} = {}: {}; it has {}", s.name, hex(Bytes(s.value)),
                          status_text(r), hex(setting_found_.view())),
              now);
  return Step::kNone;
}

Node::Step Node::after_release_for_setting(const ExplicitResult&, TimePoint) {
  // "Not allocated" (0x0B) or done: either way no poll connection is left.
  poll_allocated_ = poll_requested_ = false;
  return Step::kWriteSetting;
}

Node::Step Node::after_verify_setting(const ExplicitResult& r, TimePoint now) {
  const auto& s = config_.profile.settings[setting_index_];
  if (!std::equal(r.data.view().begin(), r.data.view().end(), s.value.begin(), s.value.end())) {
    enter_fault(NodeState::kConfigurationFault,
                fmt::format("{} reads {} after the device took {}", s.name, hex(r.data.view()),
                            hex(Bytes(s.value))),
                now);
    return Step::kNone;
  }
  settings_in_force_[setting_index_].assign(r.data.view().begin(), r.data.view().end());
  ++setting_index_;
  return first_setting_step();
}

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
    explicit_epr_ = epr;
    return Step::kPollEpr;
  }
  poll_epr_ = epr;
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

Duration Node::input_epr_asked() const {
  const auto& in = config_.profile.input_connection;
  if (!in) return Duration::zero();
  return in->strobed() ? config_.expected_packet_rate : in->expected_packet_rate;
}

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
    cos_allocated_ = true;
    return cos_step_after(Step::kAllocateCos);
  }
  const std::string_view kind = to_string(config_.profile.input_connection->kind);
  return io_allocate_refused(
      r, now, fmt::format("Allocate of the {} connection (choice 0x{:02X})", kind, cos_choice()),
      fmt::format("; the node's connection = \"{}\" needs it", kind), cos_release_tried_,
      cos_requested_, Step::kReleaseCosForAllocate);
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
        cos_path_refusal_ = fmt::format("; Set of {} to {} refused: {}", target.name,
                                        hex(Bytes(cos.produced_path)), status_text(r));
        log_.info("{}: the size tells whether the device's own path serves",
                  cos_path_refusal_.substr(2));
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
                                cos.produced_size, cos_path_refusal_),
                    now);
        return Step::kNone;
      }
      break;
    }
    case Step::kAckTimer:
    case Step::kRetryLimit: {
      const auto v = r.ok() ? read_uint(r.data.view()) : std::nullopt;
      if (!v) {
        ack_handler_unread_ = true;
        log_.info("{} not read ({}): taking the default, {}", target.name,
                  r.ok() ? hex(r.data.view()) : status_text(r),
                  step == Step::kAckTimer ? "20 ms" : "1 retry");
      } else if (step == Step::kAckTimer) {
        cos_asked_.ack_timer = milliseconds(*v);
      } else {
        cos_asked_.retry_limit = static_cast<std::uint8_t>(std::min<std::uint32_t>(*v, 255));
      }
      break;
    }
    case Step::kCosEpr: {
      // As the poll's: the value the device returned is the one it uses.
      const Duration epr = returned_epr(r, input_epr_asked());
      cos_asked_.expected_packet_rate = epr;
      if (cos_) cos_->set_expected_packet_rate(epr);
      break;
    }
    default:
      break;
  }
  return cos_step_after(step);
}

void Node::on_keepalive_result(const ExplicitResult& r, TimePoint now) {
  if (r.ok() || r.error == Errc::kDeviceError) {
    if (r.ok() && !keepalive_reads_status_ && r.data.size() == 1) {
      identity_.state = r.data[0];
      if (device_state_ != r.data[0]) {
        device_state_ = r.data[0];
        observer_.on_device_state(config_.mac, r.data[0], now);
      }
    }
    if (r.ok() && keepalive_reads_status_ && r.data.size() == 2) {
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
  if (now - last_explicit_answer_ >= 4 * explicit_epr_) {
    lose(fmt::format("explicit connection lost: no answer for {} ms (4 x EPR; {})",
                     std::chrono::duration_cast<milliseconds>(now - last_explicit_answer_).count(),
                     status_text(r)),
         now);
    return;
  }
  keepalive_at_ = now;
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

void Node::idle_poll_before_release(TimePoint now) {
  // Frames written to the port leave in the order written: the Release
  // that follows reaches the device after this poll.
  stray_poll_responses_ = poll_outstanding_ ? 2 : 1;
  const bool idle = idle_;
  idle_ = true;
  send_poll(now);
  idle_ = idle;
  // Its answer is a stray, counted above: no poll of the node's own waits.
  poll_outstanding_ = false;
  poll_deadline_ = kNever;
}

void Node::device_fault(std::string reason, TimePoint now) {
  enter_fault(NodeState::kDeviceFault, std::move(reason), now);
}

void Node::lose_and_release(std::string reason, TimePoint now) {
  // The poll connection lives: the outputs go to the device's idle state at
  // once rather than after its own watchdog, and what the device holds is
  // released (the node is allocated afresh after the back-off).
  if (state_ == NodeState::kOnline) idle_poll_before_release(now);
  const std::uint8_t held = held_connections();
  lose(std::move(reason), now);
  if (held != 0) release(Step::kReleaseFault, held, now);
}

void Node::go_online(TimePoint now) {
  retry_delay_ = port_.allocate_retry_min;
  stray_poll_responses_ = 0;
  cos_consecutive_errors_ = 0;
  poll_outstanding_ = false;
  poll_unanswered_ = false;
  consecutive_errors_ = 0;
  last_response_ = now;
  last_explicit_answer_ = now;
  next_poll_ = next_poll_slot(now);
  keepalive_at_ = now + explicit_epr_;
  io_reassembler_.reset();
  std::string reason =
      fmt::format("polled every {} ms; EPR {} ms (explicit {} ms); {} B out, {} B in",
                  std::chrono::duration_cast<milliseconds>(config_.poll_period).count(),
                  std::chrono::duration_cast<milliseconds>(poll_epr_).count(),
                  std::chrono::duration_cast<milliseconds>(explicit_epr_).count(),
                  config_.profile.consumed_size, config_.profile.produced_size);
  if (produced_from_fallback_ || consumed_from_fallback_) {
    // Worth knowing about a device: it refused Connection 2 attributes 7/8.
    reason +=
        fmt::format(" (sizes read from {} and {})", size_attribute(true, produced_from_fallback_),
                    size_attribute(false, consumed_from_fallback_));
  }
  if (cos_) {
    const CosSettings& c = cos_->settings();
    const InputKind kind = config_.profile.input_connection->kind;
    reason += fmt::format(
        "; inputs {} (EPR {} ms, {})",
        kind == InputKind::kCyclic          ? "cyclic"
        : kind == InputKind::kChangeOfState ? "on change of state"
                                            : "bit-strobed",
        to_ms(c.expected_packet_rate),
        kind == InputKind::kBitStrobe ? std::string("strobed with the port's other nodes")
        : c.ack_suppressed
            ? std::string("acknowledgment suppressed")
            : fmt::format("acknowledged: the device retries after {} ms, {} time(s){}",
                          to_ms(c.ack_timer), unsigned{c.retry_limit},
                          ack_handler_unread_ ? " (defaults: its Acknowledge "
                                                "Handler not read)"
                                              : ""));
  }
  if (!identity_state_supported_) reason += "; Identity.State not supported: state unknown";
  set_state(NodeState::kOnline, std::move(reason), now);
  // Outputs set before the node came online go out with the first poll.
  send_poll(now);
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
