#include "adapters/sim/generic/group2_slave.hpp"

#include <algorithm>
#include <array>
#include <utility>

#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::sim {

using devicenet::BodyFormat;
using devicenet::CommFaultedLayout;
using devicenet::CommFaultedMessage;
using devicenet::DuplicateMacCheck;
using devicenet::ExplicitFragmentSender;
using devicenet::ExplicitReassembler;
using devicenet::Group1Message;
using devicenet::Group2Message;
using devicenet::Group4Message;
using devicenet::MacId;
using devicenet::MessageGroup;
using devicenet::OfflineOwnershipMessage;
using devicenet::OwnershipIdentity;

namespace {

ExplicitFragmentSender::Config sender_config(const Group2Options& o) noexcept {
  ExplicitFragmentSender::Config c;
  c.ack_timeout = o.fragment_ack_timeout;
  return c;
}

// Unconnected-port additional code: invalid Group 2 only request (bridge/PROTOCOL.md §3).
constexpr std::uint8_t kInvalidGroup2Request = 0x03;
constexpr std::uint8_t kFragBit = 0x80;

}  // namespace

const char* to_string(Group2Slave::NetworkState s) noexcept {
  switch (s) {
    case Group2Slave::NetworkState::kOff:
      return "off";
    case Group2Slave::NetworkState::kDuplicateMacCheck:
      return "duplicate MAC check";
    case Group2Slave::NetworkState::kOnline:
      return "online";
    case Group2Slave::NetworkState::kCommunicationFault:
      return "communication fault";
  }
  return "?";
}

Group2Slave::Group2Slave(can::FrameSink& sink, Group2Options options, Logger log) noexcept
    : sink_(sink),
      log_(std::move(log)),
      options_(options),
      dup_check_(MacId{}, duplicate_mac_config()),
      sender_(sender_config(options)) {}

DuplicateMacCheck::Config Group2Slave::duplicate_mac_config() const noexcept {
  DuplicateMacCheck::Config c;
  c.window = options_.duplicate_mac_window;
  c.physical_port = 0;
  c.vendor_id = options_.vendor_id;
  c.serial_number = options_.serial_number;
  return c;
}

bool Group2Slave::on_io_message(Group2Message, const can::CanFrame&, TimePoint) noexcept {
  return false;
}

void Group2Slave::start_up(TimePoint now, PowerUpCause cause) noexcept {
  ++counters_.restarts;
  power_up_device(now, cause);
  reassembler_.reset();
  sender_.cancel();
  drop_delayed();
  offline_owner_ = {};
  dup_check_ = DuplicateMacCheck(device_mac(), duplicate_mac_config());
  network_ = NetworkState::kDuplicateMacCheck;
  log_.debug("power-up with MAC {}: duplicate MAC check", device_mac().value());
  const can::CanFrame request = dup_check_.start(now);
  sink_.send(request, now);
}

void Group2Slave::send(std::uint32_t id, Bytes payload, TimePoint now) noexcept {
  auto frame = can::CanFrame::make(id, payload);
  if (frame.ok()) sink_.send(*frame, now);
}

std::uint32_t Group2Slave::response_id() const noexcept {
  return devicenet::group2_id(device_mac(), Group2Message::kSlaveExplicitResponse);
}

void Group2Slave::enter_communication_fault() noexcept {
  network_ = NetworkState::kCommunicationFault;
  sender_.cancel();
  reassembler_.reset();
  drop_delayed();
  log_.debug("duplicate MAC {} detected: communication fault", device_mac().value());
}

void Group2Slave::drop_delayed() noexcept {
  delayed_responses_.clear();
  delayed_polls_.clear();
}

// ---------------------------------------------------------------------------

void Group2Slave::on_timer(TimePoint now) noexcept {
  if (network_ == NetworkState::kOff || network_ == NetworkState::kCommunicationFault) {
    advance_device(now);
    return;
  }
  if (network_ == NetworkState::kDuplicateMacCheck) {
    advance_device(now);
    if (now < dup_check_.deadline()) return;
    if (auto frame = dup_check_.on_timer(now)) sink_.send(*frame, now);
    if (dup_check_.state() == DuplicateMacCheck::State::kOnline) {
      network_ = NetworkState::kOnline;
      log_.debug("online");
    } else if (dup_check_.state() == DuplicateMacCheck::State::kDuplicate) {
      enter_communication_fault();
    }
    return;
  }
  if (!send_due(now)) return;
  if (sender_.active() && now >= sender_.deadline()) {
    switch (sender_.on_timer(now)) {
      case ExplicitFragmentSender::Step::kSend:
        send(response_id(), sender_.frame(), now);
        break;
      case ExplicitFragmentSender::Step::kFailed:
        ++counters_.fragment_transfers_failed;
        break;
      case ExplicitFragmentSender::Step::kNone:
      case ExplicitFragmentSender::Step::kComplete:
        break;
    }
  }
  const ConnectionSet& set = connection_set();
  const auto explicit_before = set.explicit_connection().state;
  const auto poll_before = set.poll_connection().state;
  const auto cos_before = set.cos_connection().state;
  device_timer(now);
  if (set.explicit_connection().state != explicit_before ||
      set.poll_connection().state != poll_before || set.cos_connection().state != cos_before) {
    log_.debug("watchdog: explicit {} -> {}, poll {} -> {}, change of state {} -> {}, owner {}",
               static_cast<int>(explicit_before), static_cast<int>(set.explicit_connection().state),
               static_cast<int>(poll_before), static_cast<int>(set.poll_connection().state),
               static_cast<int>(cos_before), static_cast<int>(set.cos_connection().state),
               set.owner());
  }
  if (!set.explicit_established()) {
    sender_.cancel();
    reassembler_.reset();
  }
}

TimePoint Group2Slave::next_deadline() const noexcept {
  TimePoint t = process_deadline();
  switch (network_) {
    case NetworkState::kOff:
    case NetworkState::kCommunicationFault:
      return t;
    case NetworkState::kDuplicateMacCheck:
      return std::min(t, dup_check_.deadline());
    case NetworkState::kOnline:
      break;
  }
  return std::min({t, sender_.deadline(), device_deadline(), delayed_responses_.deadline(),
                   delayed_polls_.deadline()});
}

// ---------------------------------------------------------------------------

void Group2Slave::on_frame(const can::CanFrame& frame, TimePoint now) noexcept {
  if (network_ == NetworkState::kOff) {
    ++counters_.frames_ignored;
    return;
  }
  if (network_ == NetworkState::kCommunicationFault) {
    on_offline(frame, now);
    return;
  }
  // A frame arriving after a deadline does not rescue what expired.
  if (now >= next_deadline()) on_timer(now);

  auto id = devicenet::decode_identifier(frame.id);
  if (!id.ok()) {
    ++counters_.frames_ignored;
    return;
  }
  if (id->group == MessageGroup::k1) {  // other slaves' messages
    ++counters_.frames_not_addressed;
    return;
  }
  if (id->group != MessageGroup::k2) {  // UCMM (Group 3) and the Group 4 offline set
    ++counters_.frames_ignored;
    return;
  }
  const auto message = static_cast<Group2Message>(id->message_id);
  if (message == Group2Message::kMasterBitStrobeCommand) {
    // Its MAC is the master's: the device's when the master owns its set.
    const bool ours = network_ == NetworkState::kOnline && connection_set().owned() &&
                      id->mac.value() == connection_set().owner();
    if (!ours) {
      ++counters_.frames_not_addressed;
    } else if (!on_io_message(message, frame, now)) {
      ++counters_.frames_ignored;
    }
    return;
  }
  if (id->mac != device_mac()) {
    ++counters_.frames_not_addressed;
    return;
  }
  if (message == Group2Message::kDuplicateMacCheck) {
    on_duplicate_mac(frame, now);
    return;
  }
  if (network_ != NetworkState::kOnline) {  // nothing but the check before going online
    ++counters_.frames_ignored;
    return;
  }
  switch (message) {
    case Group2Message::kUnconnectedExplicitRequest:
      on_unconnected(frame, now);
      break;
    case Group2Message::kMasterExplicitRequest:
      on_explicit(frame, now);
      break;
    case Group2Message::kMasterIoPoll:
      on_poll(frame, now);
      break;
    default:  // multicast poll, COS ack: the device's, if it has them
      if (!on_io_message(message, frame, now)) ++counters_.frames_ignored;
      break;
  }
}

void Group2Slave::on_duplicate_mac(const can::CanFrame& frame, TimePoint now) noexcept {
  auto m = devicenet::decode_duplicate_mac(frame.payload());
  if (!m.ok()) {
    ++counters_.frames_ignored;
    return;
  }
  if (auto response = dup_check_.on_message(*m)) sink_.send(*response, now);
  if (dup_check_.state() == DuplicateMacCheck::State::kDuplicate) {
    go_offline(now);
    enter_communication_fault();
  }
}

// Group 2 only unconnected port: Allocate and Release to the DeviceNet object.
void Group2Slave::on_unconnected(const can::CanFrame& frame, TimePoint now) noexcept {
  const Bytes p = frame.payload();
  if (p.size() < 2 || (p[0] & kFragBit) != 0 || (p[1] & cip::kResponseFlag) != 0) {
    ++counters_.frames_ignored;
    return;
  }
  const std::uint8_t header = static_cast<std::uint8_t>(p[0] & 0x7F);
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> out{};
  std::size_t n = 0;
  auto request = devicenet::decode_request(p.subspan(1), BodyFormat::k8_8);
  const std::uint8_t service = p[1];
  const bool allocation_service = service == cip::code(cip::Service::kAllocateMasterSlave) ||
                                  service == cip::code(cip::Service::kReleaseMasterSlave);
  if (!allocation_service || !request.ok() || request->class_id != devicenet::kDeviceNetClass ||
      request->instance_id != 1) {
    auto e = devicenet::encode_error_response(cip::GeneralStatus::kResourceUnavailable,
                                              kInvalidGroup2Request, out);
    n = e.ok() ? *e : 0;
  } else {
    n = execute(*request, static_cast<std::uint8_t>(header & 0x3F), now, out);
  }
  if (n > 0 && out[0] == (cip::code(cip::Service::kErrorResponse) | cip::kResponseFlag)) {
    ++counters_.requests_refused;
  }
  respond(true, header, Bytes(out.data(), n), now);
}

void Group2Slave::on_explicit(const can::CanFrame& frame, TimePoint now) noexcept {
  const Bytes p = frame.payload();
  if (!connection_set().explicit_established() || p.empty()) {
    ++counters_.frames_ignored;
    return;
  }
  connection_set().consumed(connection_instance::kExplicit, now);
  const std::uint8_t header = p[0];
  if ((header & kFragBit) == 0) {
    handle_explicit_message(header, p.subspan(1), now);
    return;
  }
  if (p.size() < 2) {
    ++counters_.frames_ignored;
    return;
  }
  // An ack of a response fragment, or a fragment of a request.
  if (devicenet::decode_fragment_byte(p[1]).type == devicenet::FragmentType::kAck) {
    switch (sender_.on_ack(p, now)) {
      case ExplicitFragmentSender::Step::kSend:
        send(response_id(), sender_.frame(), now);
        break;
      case ExplicitFragmentSender::Step::kFailed:
        ++counters_.fragment_transfers_failed;
        break;
      case ExplicitFragmentSender::Step::kNone:
        ++counters_.frames_ignored;
        break;
      case ExplicitFragmentSender::Step::kComplete:
        break;
    }
    return;
  }
  switch (reassembler_.on_fragment(p)) {
    case ExplicitReassembler::Outcome::kDropped:
      ++counters_.frames_ignored;
      break;
    case ExplicitReassembler::Outcome::kRepeated:
      // The last fragment again (its ack lost, for the reassembler): a
      // device that never acks the last fragment does not ack it now either.
      if (!reassembler_.in_progress() && options_.no_ack_of_last_request_fragment) {
        ++counters_.frames_ignored;
        break;
      }
      send(response_id(), reassembler_.ack(), now);
      break;
    case ExplicitReassembler::Outcome::kAccepted:
    case ExplicitReassembler::Outcome::kOverflow:
      send(response_id(), reassembler_.ack(), now);
      break;
    case ExplicitReassembler::Outcome::kRestarted:
      if (reassembler_.in_progress()) {
        send(response_id(), reassembler_.ack(), now);
      } else {
        ++counters_.frames_ignored;
      }
      break;
    case ExplicitReassembler::Outcome::kComplete:
      // Some devices answer the last fragment with the response alone.
      if (!options_.no_ack_of_last_request_fragment) {
        send(response_id(), reassembler_.ack(), now);
      }
      handle_explicit_message(header, reassembler_.message(), now);
      break;
  }
}

void Group2Slave::handle_explicit_message(std::uint8_t header, Bytes message,
                                          TimePoint now) noexcept {
  if (message.empty() || (message[0] & cip::kResponseFlag) != 0) {
    ++counters_.frames_ignored;
    return;
  }
  ++counters_.explicit_requests;
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> out{};
  std::size_t n = 0;
  auto request = devicenet::decode_request(message, BodyFormat::k8_8);
  if (request.ok()) {
    n = execute(*request, static_cast<std::uint8_t>(header & 0x3F), now, out);
  } else {
    auto e = devicenet::encode_error_response(cip::GeneralStatus::kNotEnoughData,
                                              cip::kNoAdditionalCode, out);
    n = e.ok() ? *e : 0;
  }
  if (n > 0 && out[0] == (cip::code(cip::Service::kErrorResponse) | cip::kResponseFlag)) {
    ++counters_.requests_refused;
  }
  respond(false, header, Bytes(out.data(), n), now);
}

void Group2Slave::respond(bool unconnected, std::uint8_t header, Bytes message,
                          TimePoint now) noexcept {
  // What the request left to do (a restart) waits for its response.
  const PendingAction then = take_pending_action();
  const Duration delay = options_.explicit_response_delay;
  if (delay <= Duration::zero()) {
    transmit_response(unconnected, header, message, now);
    after_response(then, now);
    return;
  }
  DelayedResponse r;
  r.unconnected = unconnected;
  r.header = header;
  r.then = then;
  if (r.message.assign(message) && delayed_responses_.push(now + delay, r)) return;
  ++counters_.responses_dropped;
  log_.debug("response to header {:#04x} dropped: {} responses already wait", header,
             delayed_responses_.size());
  after_response(then, now);
}

void Group2Slave::transmit_response(bool unconnected, std::uint8_t header, Bytes message,
                                    TimePoint now) noexcept {
  if (!unconnected) {
    send_explicit_response(header, message, now);
    return;
  }
  // The unconnected port's responses are never fragmented.
  std::array<std::uint8_t, 8> payload{};
  payload[0] = static_cast<std::uint8_t>(header & 0x7F);
  const std::size_t len = std::min<std::size_t>(message.size(), devicenet::kMaxUnfragmentedMessage);
  std::copy_n(message.begin(), len, payload.begin() + 1);
  send(response_id(), Bytes(payload.data(), len + 1), now);
}

bool Group2Slave::send_due(TimePoint now) noexcept {
  if (std::min(delayed_polls_.deadline(), delayed_responses_.deadline()) > now) return true;
  // The earlier of the two queues first: what is due leaves in time order.
  InlineBytes<8> poll;
  DelayedResponse r;
  for (;;) {
    if (delayed_polls_.deadline() <= delayed_responses_.deadline()) {
      if (!delayed_polls_.pop_due(now, poll)) return true;
      send_poll_response(poll.view(), now);
      continue;
    }
    if (!delayed_responses_.pop_due(now, r)) return true;
    transmit_response(r.unconnected, r.header, r.message.view(), now);
    after_response(r.then, now);
    if (network_ != NetworkState::kOnline) return false;
  }
}

// Responses echo the request's XID and MAC (request[0] & 0x7F); longer than
// one frame, they go out in acknowledged fragments.
void Group2Slave::send_explicit_response(std::uint8_t header, Bytes message,
                                         TimePoint now) noexcept {
  const auto response_header = static_cast<std::uint8_t>(header & 0x7F);
  if (message.size() <= devicenet::kMaxUnfragmentedMessage) {
    std::array<std::uint8_t, 8> payload{};
    payload[0] = response_header;
    std::copy(message.begin(), message.end(), payload.begin() + 1);
    send(response_id(), Bytes(payload.data(), message.size() + 1), now);
    return;
  }
  sender_.cancel();
  if (sender_.start(devicenet::decode_header(response_header), message, now).ok()) {
    send(response_id(), sender_.frame(), now);
  } else {
    ++counters_.fragment_transfers_failed;
  }
}

void Group2Slave::after_response(PendingAction action, TimePoint now) noexcept {
  switch (action) {
    case PendingAction::kNone:
      return;
    case PendingAction::kRestartFactoryDefaults:
      restore_factory_defaults();
      [[fallthrough]];
    case PendingAction::kRestart:
      log_.debug("reset: restarting");
      restart(now);
      return;
  }
}

void Group2Slave::on_poll(const can::CanFrame& frame, TimePoint now) noexcept {
  PollResult r = poll(frame.payload(), now);
  switch (r.outcome) {
    case PollOutcome::kNotEstablished:
      ++counters_.polls_ignored;
      return;
    case PollOutcome::kOversize:
      ++counters_.polls_oversize;
      return;
    case PollOutcome::kApplied:
      ++counters_.polls_applied;
      break;
    case PollOutcome::kIdle:
      ++counters_.polls_idle;
      break;
    case PollOutcome::kInvalid:
      ++counters_.polls_invalid;
      break;
    case PollOutcome::kMajorFault:
      ++counters_.polls_major_fault;
      break;
  }
  const Duration delay = options_.poll_response_delay;
  if (delay <= Duration::zero()) {
    send_poll_response(r.response.view(), now);
  } else if (!delayed_polls_.push(now + delay, r.response)) {
    ++counters_.responses_dropped;
  }
}

void Group2Slave::send_poll_response(Bytes payload, TimePoint now) noexcept {
  send(devicenet::group1_id(Group1Message::kSlavePollResponse, device_mac()), payload, now);
}

// ---------------------------------------------------------------------------
// Group 4 Offline Connection Set, in Communication Fault only (see the header).

bool Group2Slave::names_this_node(std::uint16_t vendor_id,
                                  std::uint32_t serial_number) const noexcept {
  return vendor_id == options_.vendor_id && serial_number == options_.serial_number;
}

void Group2Slave::on_offline(const can::CanFrame& frame, TimePoint now) noexcept {
  auto id = devicenet::decode_identifier(frame.id);
  if (!options_.offline.supported || !id.ok() || id->group != MessageGroup::k4) {
    ++counters_.frames_ignored;
    return;
  }
  switch (static_cast<Group4Message>(id->message_id)) {
    case Group4Message::kOfflineOwnershipRequest: {
      auto m = devicenet::decode_offline_ownership(frame.payload());
      if (!m.ok() || m->response) break;
      on_offline_ownership(*m, now);
      return;
    }
    case Group4Message::kCommFaultedRequest: {
      auto m = devicenet::decode_comm_faulted(frame.payload());
      if (!m.ok() || m->response) break;
      on_comm_faulted(*m, now);
      return;
    }
    case Group4Message::kCommFaultedResponse:
    case Group4Message::kOfflineOwnershipResponse:
      ++counters_.frames_not_addressed;  // other faulted nodes answering
      return;
  }
  ++counters_.frames_ignored;
}

void Group2Slave::on_offline_ownership(const OfflineOwnershipMessage& m, TimePoint now) noexcept {
  if (options_.offline.ownership_identity == OwnershipIdentity::kTarget &&
      !names_this_node(m.vendor_id, m.serial_number)) {
    ++counters_.frames_not_addressed;
    return;
  }
  const bool same_client = offline_owner_.client == m.client_mac &&
                           offline_owner_.vendor_id == m.vendor_id &&
                           offline_owner_.serial_number == m.serial_number;
  if (offline_owner_.owned && !same_client) {
    ++counters_.requests_refused;
    log_.debug("offline ownership request from MAC {} refused: owned by MAC {}",
               m.client_mac.value(), offline_owner_.client.value());
    return;
  }
  if (m.allocate == devicenet::kOfflineAllocate) {
    offline_owner_ = {true, m.client_mac, m.vendor_id, m.serial_number};
  } else if (m.allocate == devicenet::kOfflineRelease) {
    offline_owner_ = {};
  } else {
    ++counters_.frames_ignored;
    return;
  }
  log_.debug("offline connection set {} by client MAC {}",
             offline_owner_.owned ? "owned" : "released", m.client_mac.value());
  OfflineOwnershipMessage response = m;
  response.response = true;
  if (auto f = devicenet::encode_offline_ownership(response)) {
    sink_.send(*f, now);
    ++counters_.offline_responses;
  }
}

void Group2Slave::on_comm_faulted(const CommFaultedMessage& m, TimePoint now) noexcept {
  const OfflineOptions& o = options_.offline;
  bool identify = false;
  switch (m.layout) {
    case CommFaultedLayout::kShort:
    case CommFaultedLayout::kShortWithDelay:
      if (m.match && m.value != device_mac().value()) {
        ++counters_.frames_not_addressed;
        return;
      }
      identify = m.service == o.identify_service;
      break;
    case CommFaultedLayout::kLong:
      if (!names_this_node(m.vendor_id, m.serial_number)) {
        ++counters_.frames_not_addressed;
        return;
      }
      identify = m.service == o.identify_service;
      if (!identify && m.service == o.set_mac_service) {
        if (!offline_owner_.owned) {
          ++counters_.requests_refused;
          log_.debug("offline MAC change to {} refused: no ownership", m.value);
          return;
        }
        const Reply r = set_mac(m.value);
        if (!r.ok()) {
          ++counters_.requests_refused;
          log_.debug("offline MAC change to {} refused: status {:#x}", m.value,
                     static_cast<unsigned>(r.status));
          return;
        }
        CommFaultedMessage response = m;
        response.response = true;
        if (auto f = devicenet::encode_comm_faulted(response)) {
          sink_.send(*f, now);
          ++counters_.offline_responses;
        }
        // The restart below re-enters the network whether or not the MAC changed.
        (void)take_pending_action();
        log_.debug("offline MAC set to {}: duplicate MAC check again", m.value);
        restart(now);
        return;
      }
      break;
    case CommFaultedLayout::kPortVendorSerial:
      break;  // a response layout
  }
  if (!identify) {
    ++counters_.frames_ignored;
    return;
  }
  CommFaultedMessage response;
  response.layout = o.identify_response;
  response.response = true;
  response.value = device_mac().value();
  response.service = static_cast<std::uint8_t>(o.identify_service & 0x7F);
  response.physical_port = 0;
  response.vendor_id = options_.vendor_id;
  response.serial_number = options_.serial_number;
  if (auto f = devicenet::encode_comm_faulted(response)) {
    sink_.send(*f, now);
    ++counters_.offline_responses;
  }
}

}  // namespace dnbridge::sim
