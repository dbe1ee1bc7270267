// Node: its start-up as one table of steps (kStartup below). A row says
// what its step asks, when it applies, which answers it takes and where
// each leads; its handler (node_identify.cpp, node_connections.cpp) records
// what an answer says and gives its verdict. Here the requests are built and
// sent, each answer taken to its row, and a node that is left released.
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

// The start-up, in the order it runs. A row's request is built from the row
// (and its `ask`); its answer goes to the row's handler, which records what
// it says and gives a verdict: `next`, `alt`, the row again, or stop. A
// refusal (CIP error reply) goes where `on_refusal` says; no answer is
// retried twice on the explicit connection and then taken for a lost node,
// unless `on_silence` gives it to the handler (the Allocate of the explicit
// connection: an absent node, retried with back-off). A row that does not
// apply (`applies`) is passed over to its `next`.
// clang-format off
const Node::StepRow Node::kStartup[] = {
  // The explicit connection; what was left allocated from before, released.
  {.step = Step::kAllocateExplicit, .phase = NodeState::kAbsent, .verb = Verb::kAllocate, .target = kDeviceNetObject, .choice = allocation::kExplicit,
   .on_silence = OnSilence::kHandler, .handler = &Node::after_allocate_explicit, .next = Step::kAllocationInfo, .alt = Step::kReleaseStale},
  {.step = Step::kReleaseStale, .phase = NodeState::kAbsent, .verb = Verb::kRelease, .target = kDeviceNetObject, .choice = allocation::kExplicit,
   .on_silence = OnSilence::kHandler, .handler = &Node::after_release_stale},  // allocated again after a back-off
  {.step = Step::kAllocationInfo, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = cip::devicenet_object::kAllocationInformation,
   .on_refusal = OnRefusal::kGoOn, .handler = &Node::after_allocation_info, .next = Step::kVendor, .alt = Step::kReleaseStalePoll},
  {.step = Step::kReleaseStalePoll, .phase = NodeState::kIdentifying, .verb = Verb::kRelease, .target = kDeviceNetObject, .ask = &Node::ask_stale_io,
   .on_refusal = OnRefusal::kGoOn, .next = Step::kVendor},

  // The identity the scan list expects, then what the device tells of itself.
  {.step = Step::kVendor, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kVendorId,
   .on_refusal = OnRefusal::kWrongDevice, .handler = &Node::after_identity_match, .next = Step::kProductType},
  {.step = Step::kProductType, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kProductType,
   .on_refusal = OnRefusal::kWrongDevice, .handler = &Node::after_identity_match, .next = Step::kProductCode},
  {.step = Step::kProductCode, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kProductCode,
   .on_refusal = OnRefusal::kWrongDevice, .handler = &Node::after_identity_match, .next = Step::kRevision},
  {.step = Step::kRevision, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kRevision,
   .on_refusal = OnRefusal::kGoOn, .handler = &Node::after_revision, .next = Step::kSerial},
  {.step = Step::kSerial, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kSerialNumber,
   .handler = &Node::after_serial, .next = Step::kName},
  {.step = Step::kName, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kProductName,
   .on_refusal = OnRefusal::kGoOn, .handler = &Node::after_name, .next = Step::kIdentityStatus},
  {.step = Step::kIdentityStatus, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kStatus,
   .handler = &Node::after_identity_status, .next = Step::kIdentityState},
  {.step = Step::kIdentityState, .phase = NodeState::kIdentifying, .verb = Verb::kGet, .target = ident::kState,
   .handler = &Node::after_identity_state, .next = Step::kReadSetting},

  // The profile's settings, one after the other: read, written only where
  // it differs, read back. Then its checks, read and compared.
  {.step = Step::kReadSetting, .phase = NodeState::kConfiguring, .verb = Verb::kGet, .target = kProfileSetting, .applies = &Node::has_setting,
   .on_refusal = OnRefusal::kFault, .handler = &Node::after_read_setting, .next = Step::kCheckAttribute, .alt = Step::kWriteSetting},
  {.step = Step::kWriteSetting, .phase = NodeState::kConfiguring, .verb = Verb::kSet, .target = kProfileSetting, .ask = &Node::ask_setting,
   .handler = &Node::after_write_setting, .next = Step::kVerifySetting, .alt = Step::kReleasePollForSetting},
  {.step = Step::kReleasePollForSetting, .phase = NodeState::kConfiguring, .verb = Verb::kRelease, .target = kDeviceNetObject, .choice = allocation::kPoll,
   .handler = &Node::after_release_for_setting, .next = Step::kWriteSetting},
  {.step = Step::kVerifySetting, .phase = NodeState::kConfiguring, .verb = Verb::kGet, .target = kProfileSetting,
   .on_refusal = OnRefusal::kFault, .handler = &Node::after_verify_setting, .next = Step::kReadSetting},
  {.step = Step::kCheckAttribute, .phase = NodeState::kConfiguring, .verb = Verb::kGet, .target = kProfileCheck, .applies = &Node::has_check,
   .handler = &Node::after_check, .next = Step::kAllocatePoll},

  // The poll connection: allocated, its paths set where they differ.
  {.step = Step::kAllocatePoll, .phase = NodeState::kConfiguring, .verb = Verb::kAllocate, .target = kDeviceNetObject, .choice = allocation::kPoll, .ask = &Node::ask_allocate_poll,
   .handler = &Node::after_allocate_poll, .next = Step::kGetProducedPath, .alt = Step::kReleasePollForAllocate},
  {.step = Step::kReleasePollForAllocate, .phase = NodeState::kConfiguring, .verb = Verb::kRelease, .target = kDeviceNetObject, .choice = allocation::kPoll,
   .on_refusal = OnRefusal::kGoOn, .next = Step::kAllocatePoll},
  {.step = Step::kGetProducedPath, .phase = NodeState::kConfiguring, .verb = Verb::kGet, .target = conn::kPollProducedPath, .applies = &Node::has_produced_path,
   .handler = &Node::after_get_path, .next = Step::kGetConsumedPath, .alt = Step::kSetProducedPath},
  {.step = Step::kSetProducedPath, .phase = NodeState::kConfiguring, .verb = Verb::kSet, .target = conn::kPollProducedPath, .ask = &Node::ask_produced_path,
   .handler = &Node::after_set_path, .next = Step::kGetConsumedPath},
  {.step = Step::kGetConsumedPath, .phase = NodeState::kConfiguring, .verb = Verb::kGet, .target = conn::kPollConsumedPath, .applies = &Node::has_consumed_path,
   .handler = &Node::after_get_path, .next = Step::kProducedSize, .alt = Step::kSetConsumedPath},
  {.step = Step::kSetConsumedPath, .phase = NodeState::kConfiguring, .verb = Verb::kSet, .target = conn::kPollConsumedPath, .ask = &Node::ask_consumed_path,
   .handler = &Node::after_set_path, .next = Step::kProducedSize},

  // Its sizes, from Connection 2 or where the profile says the same sizes are kept.
  {.step = Step::kProducedSize, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = conn::kPollProducedSize,
   .handler = &Node::after_size, .next = Step::kConsumedSize, .alt = Step::kFallbackProducedSize},
  {.step = Step::kConsumedSize, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = conn::kPollConsumedSize,
   .handler = &Node::after_size, .next = Step::kAllocateCos, .alt = Step::kFallbackConsumedSize},
  {.step = Step::kFallbackProducedSize, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = kProfileSizeFallback,
   .handler = &Node::after_size, .next = Step::kFallbackConsumedSize},
  {.step = Step::kFallbackConsumedSize, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = kProfileSizeFallback,
   .handler = &Node::after_size, .next = Step::kAllocateCos},

  // The input connection, where the profile has one: change of state or
  // cyclic (Connection 4), or bit-strobe (Connection 3: target_of()), which
  // has no inhibit time and no Acknowledge Handler.
  {.step = Step::kAllocateCos, .phase = NodeState::kVerifying, .verb = Verb::kAllocate, .target = kDeviceNetObject, .ask = &Node::ask_allocate_cos, .applies = &Node::has_input,
   .handler = &Node::after_allocate_cos, .next = Step::kSetCosPath, .alt = Step::kReleaseCosForAllocate},
  {.step = Step::kReleaseCosForAllocate, .phase = NodeState::kVerifying, .verb = Verb::kRelease, .target = kDeviceNetObject, .ask = &Node::ask_cos_release,
   .on_refusal = OnRefusal::kGoOn, .next = Step::kAllocateCos},
  {.step = Step::kSetCosPath, .phase = NodeState::kVerifying, .verb = Verb::kSet, .target = conn::kCosProducedPath, .ask = &Node::ask_cos_path, .applies = &Node::has_input_path,
   .handler = &Node::after_cos_path, .next = Step::kCosInhibit},
  {.step = Step::kCosInhibit, .phase = NodeState::kVerifying, .verb = Verb::kSet, .target = conn::kCosInhibitTime, .ask = &Node::ask_cos_inhibit, .applies = &Node::has_input_inhibit,
   .handler = &Node::after_cos_inhibit, .next = Step::kCosSize},
  {.step = Step::kCosSize, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = conn::kCosProducedSize, .applies = &Node::has_input,
   .handler = &Node::after_cos_size, .next = Step::kAckTimer},
  {.step = Step::kAckTimer, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = ack::kAckTimer, .applies = &Node::has_ack_handler,
   .handler = &Node::after_ack_setting, .next = Step::kRetryLimit},
  {.step = Step::kRetryLimit, .phase = NodeState::kVerifying, .verb = Verb::kGet, .target = ack::kRetryLimit, .applies = &Node::has_ack_handler,
   .handler = &Node::after_ack_setting, .next = Step::kExplicitEpr},

  // The expected packet rates: the explicit connection's, then the poll
  // connection's, which starts it (its first poll follows at once), then
  // the input connection's, which starts that one.
  {.step = Step::kExplicitEpr, .phase = NodeState::kVerifying, .verb = Verb::kSet, .target = conn::kExplicitExpectedPacketRate, .ask = &Node::ask_explicit_epr,
   .on_refusal = OnRefusal::kFault, .handler = &Node::after_explicit_epr, .next = Step::kPollEpr},
  {.step = Step::kPollEpr, .phase = NodeState::kVerifying, .verb = Verb::kSet, .target = conn::kPollExpectedPacketRate, .ask = &Node::ask_poll_epr,
   .on_refusal = OnRefusal::kFault, .handler = &Node::after_poll_epr, .next = Step::kCosEpr},
  {.step = Step::kCosEpr, .phase = NodeState::kVerifying, .verb = Verb::kSet, .target = conn::kCosExpectedPacketRate, .ask = &Node::ask_cos_epr, .applies = &Node::has_input,
   .on_refusal = OnRefusal::kFault, .handler = &Node::after_cos_epr, .next = Step::kOnline},
};
// clang-format on

const Node::StepRow& Node::row(Step step) {
  for (const auto& r : kStartup) {
    if (r.step == step) return r;
  }
  // Outside start-up: the keep-alive and the releases have no row.
  static constexpr StepRow kNoRow{};
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
  releases_.begin();
  send_release(step, choice, now);
}

void Node::send_release(Step step, std::uint8_t choice, TimePoint now) {
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
  // What an attempt learns is its own: paths, sizes and refusals from an
  // earlier one would otherwise pile up in the reasons.
  path_refusal_.clear();
  produced_path_in_force_.clear();
  consumed_path_in_force_.clear();
  produced_size_.reset();
  consumed_size_.reset();
  produced_from_fallback_ = consumed_from_fallback_ = false;
  size_refusal_.clear();
  input_.begin_attempt();
  ++counters_.allocate_attempts;
  enter(Step::kAllocateExplicit, now);
}

void Node::enter(Step step, TimePoint now) {
  while (step != Step::kNone) {
    if (step == Step::kOnline) {
      go_online(now);
      return;
    }
    const StepRow& r = row(step);
    if (r.applies == nullptr || (this->*r.applies)()) {
      run(r, now);
      return;
    }
    step = r.next;
  }
}

void Node::run(const StepRow& r, TimePoint now) {
  if (r.phase != NodeState::kAbsent && r.phase != state_) {
    set_state(r.phase, std::string(phase_reason(r.phase)), now);
  }
  Ask ask;
  ask.choice = r.choice;
  if (r.ask != nullptr) (this->*r.ask)(ask, now);
  switch (r.verb) {
    case Verb::kAllocate: {
      const std::array<std::uint8_t, 2> data{ask.choice, port_.master_mac.value()};
      RequestMessage m;
      m.service = cip::code(cip::Service::kAllocateMasterSlave);
      m.class_id = kDeviceNetObject.class_id;
      m.instance_id = 1;
      m.data = Bytes(data);
      issue(r.step, m, true, now);
      return;
    }
    case Verb::kRelease:
      // A poll connection released during the start-up may be one left from
      // before (a restart, or a bus lost and back, within the device's own
      // timeout), still carrying the outputs last commanded: idle first.
      if ((ask.choice & allocation::kPoll) != 0) poll_.send_idle_before_release(now);
      release(r.step, ask.choice, now);
      return;
    case Verb::kGet:
      get(r.step, target_of(r.step), now);
      return;
    case Verb::kSet: {
      const cip::AttributeRef target = target_of(r.step);
      RequestMessage m;
      m.service = cip::code(cip::Service::kSetAttributeSingle);
      m.class_id = target.class_id;
      m.instance_id = target.instance_id;
      m.attribute = target.attribute;
      m.data = ask.value.view();
      issue(r.step, m, false, now, ask.timeout);
      return;
    }
  }
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
  if (step == Step::kReleaseFault || step == Step::kReleaseShutdown) {
    on_release_result(step, r, now);
    return;
  }
  record_answer(r, now);
  if (step == Step::kKeepAlive) {
    on_keepalive_result(r, now);
    return;
  }
  const StepRow& rule = row(step);
  if (r.error && r.error != Errc::kDeviceError && rule.on_silence == OnSilence::kResend) {
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
  switch (judge(rule, r, now)) {
    case Verdict::kNext:
      enter(rule.next, now);
      return;
    case Verdict::kAlt:
      enter(rule.alt, now);
      return;
    case Verdict::kAgain:
      enter(rule.step, now);
      return;
    case Verdict::kStop:
      return;
  }
}

void Node::record_answer(const ExplicitResult& r, TimePoint now) {
  if (r.error == Errc::kDeviceError) record_device_error(r, now);
  if (r.error == Errc::kTimeout) record(NodeError::Kind::kExplicitTimeout, now);
  if (r.error == Errc::kAborted) record(NodeError::Kind::kExplicitAborted, now);
  if (r.error == Errc::kMalformed) record(NodeError::Kind::kExplicitMalformed, now);
}

Node::Verdict Node::judge(const StepRow& rule, const ExplicitResult& r, TimePoint now) {
  if (r.error == Errc::kDeviceError) {
    const cip::AttributeRef target = target_of(rule.step);
    switch (rule.on_refusal) {
      case OnRefusal::kFault:
        enter_fault(NodeState::kConfigurationFault,
                    fmt::format("device refused {} {}: {}{}", verb_name(last_request_.service),
                                target.name, status_text(r), setting_expectation(rule.step)),
                    now);
        return Verdict::kStop;
      case OnRefusal::kWrongDevice:
        enter_fault(NodeState::kWrongDevice,
                    fmt::format("{} unreadable: {}", target.name, status_text(r)), now);
        return Verdict::kStop;
      case OnRefusal::kGoOn:
        log_.debug("{} {} refused ({}): going on", verb_name(last_request_.service), target.name,
                   status_text(r));
        break;
      case OnRefusal::kHandler:
        break;
    }
  }
  return rule.handler != nullptr ? (this->*rule.handler)(r, now) : Verdict::kNext;
}

void Node::on_release_result(Step step, const ExplicitResult& r, TimePoint now) {
  // What a Release after a loss or a fault answers (a refusal of what the
  // device no longer holds, or nothing from a device gone) is not news: the
  // last error stays the one that made the node leave.
  if (!last_request_data_.empty()) {
    const bool refused_whole = r.error == Errc::kDeviceError &&
                               r.general_status == cip::GeneralStatus::kAlreadyInRequestedMode;
    const std::uint8_t next = releases_.after(last_request_data_.view()[0], refused_whole);
    if (next != 0) {
      send_release(step, next, now);
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
}

}  // namespace dnbridge::devicenet
