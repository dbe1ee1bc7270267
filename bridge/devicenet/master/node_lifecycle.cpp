// Node: its start-up as one ordered table of steps (kStartup below), each
// step's request built and sent, and its answer taken to the row's handler
// (node_identify.cpp, node_connections.cpp) or to where the row leads.
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
  // The choice of kAllocateCos is the profile's (InputLink::choice()).
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
                                   (poll_.allocation().held() ? allocation::kPoll : 0) |
                                   (input_.allocation().held() ? input_.connection_bits() : 0));
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
  poll_.send_idle_before_release(now);
  release(Step::kReleaseShutdown,
          static_cast<std::uint8_t>(allocation::kExplicit | allocation::kPoll |
                                    input_.connection_bits()),
          now);
}

void Node::attempt_allocate(TimePoint now) {
  retry_at_ = kNever;
  step_timeouts_ = 0;
  poll_.begin_attempt();
  setting_retried_ = false;
  // What an attempt learns is its own: paths and refusals from an earlier one
  // would otherwise pile up in the reasons.
  path_refusal_.clear();
  produced_path_in_force_.clear();
  consumed_path_in_force_.clear();
  input_.begin_attempt();
  ++counters_.allocate_attempts;
  run(Step::kAllocateExplicit, now);
}

void Node::run(Step step, TimePoint now) {
  const StepRow& r = row(step);
  if (r.phase != NodeState::kAbsent && r.phase != state_) {
    set_state(r.phase, std::string(phase_reason(r.phase)), now);
  }
  if (step == Step::kAllocatePoll) poll_.allocation().requested = true;
  if (step == Step::kAllocateCos) input_.allocation().requested = true;
  if (step == Step::kCosEpr) {
    // Setting EPR starts production: a message may come before the answer.
    input_.start_consuming(now);
  }
  switch (r.verb) {
    case Verb::kAllocate: {
      const std::uint8_t choice = step == Step::kAllocateCos ? input_.choice() : r.choice;
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
                                  : step == Step::kReleaseCosForAllocate ? input_.connection_bits()
                                                                         : r.choice;
      // A poll connection released during the start-up may be one left from
      // before (a restart, or a bus lost and back, within the device's own
      // timeout), still carrying the outputs last commanded: idle first.
      if ((choice & allocation::kPoll) != 0) poll_.send_idle_before_release(now);
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
          value.assign(Bytes(uint_le(to_ms(input_.epr_asked()))));
          timeout = std::min(client_.response_timeout(), 2 * poll_.epr());
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
  if (result.ok() || result.error == Errc::kDeviceError) keep_alive_.answered(now);
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
      connected_ = false;
      poll_.allocation().forget();
      input_.allocation().forget();
      input_.stop();
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

}  // namespace dnbridge::devicenet
