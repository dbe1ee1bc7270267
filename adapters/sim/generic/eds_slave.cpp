#include "adapters/sim/generic/eds_slave.hpp"

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "adapters/sim/generic/attribute_codec.hpp"
#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::sim {
namespace {

using cip::GeneralStatus;
using devicenet::Group1Message;
using devicenet::Group2Message;
using devicenet::MacId;
namespace alloc = devicenet::allocation;

// The explicit connection's produced and consumed size (attributes 7/8):
// the longest message it reassembles.
constexpr std::uint16_t kExplicitMessageSize = devicenet::kMaxExplicitMessage;

// The assembly an [IO_Info] input or output names; 0 for none.
std::uint16_t io_assembly(const profiles::eds::EdsFile& file,
                          const profiles::eds::IoData* data) noexcept {
  if (data == nullptr) return 0;
  const profiles::eds::Assembly* a = file.assembly_at(data->path);
  if (a == nullptr || !a->path.instance_id || *a->path.instance_id > 0xFFFF) return 0;
  return static_cast<std::uint16_t>(*a->path.instance_id);
}

// What an I/O connection's assembly may be: 1..8 bytes, one frame (no I/O
// fragmentation here).
bool fits_one_frame(std::size_t size) noexcept { return size > 0 && size <= kMaxPollData; }

// The parameters of the outputs' safe state, by this simulator's convention
// (eds_slave.hpp), when the EDS has all four.
std::optional<std::array<unsigned, 4>> safe_state_params(
    const profiles::eds::EdsFile& file) noexcept {
  std::array<unsigned, 4> numbers{};
  const std::array<std::string_view, 4> names{"Output fault action", "Output fault value",
                                              "Output idle action", "Output idle value"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const profiles::eds::Param* p = file.param(names[i]);
    if (p == nullptr) return std::nullopt;
    numbers[i] = p->number;
  }
  return numbers;
}

Group2Options wire_options(const profiles::eds::EdsFile& file, const EdsSlaveOptions& o) noexcept {
  Group2Options w = o.wire;
  w.vendor_id = file.device.vendor_code;
  w.serial_number = o.serial_number;
  return w;
}

}  // namespace

// The defaults are checked as a path is (assembly_allowed): one that does
// not fit a frame is none, rather than data cut short on the wire while
// attributes 7/8 say its full size.
EdsSlave::IoDefaults EdsSlave::io_defaults(const EdsObjects& objects) noexcept {
  const profiles::eds::EdsFile& file = objects.file();
  const auto fitting = [&](const profiles::eds::IoData* data) -> std::uint16_t {
    const std::uint16_t a = io_assembly(file, data);
    return a != 0 && fits_one_frame(objects.assembly_data(a).size()) ? a : 0;
  };
  IoDefaults d;
  d.choices = alloc::kExplicit | alloc::kPoll;
  const profiles::eds::IoInfo& io = file.io;
  if (const auto* poll = io.connection(profiles::eds::ConnectionKind::kPoll)) {
    d.poll_input = fitting(io.input(poll->input));
    d.poll_output = fitting(io.output(poll->output));
  }
  const auto* cos = io.connection(profiles::eds::ConnectionKind::kChangeOfState);
  const auto* cyclic = io.connection(profiles::eds::ConnectionKind::kCyclic);
  if (cos != nullptr) d.choices |= alloc::kChangeOfState | alloc::kAckSuppression;
  if (cyclic != nullptr) d.choices |= alloc::kCyclic | alloc::kAckSuppression;
  if (const auto* produced = cos != nullptr ? cos : cyclic) {
    d.cos_input = fitting(io.input(produced->input));
  }
  if (const auto* strobe = io.connection(profiles::eds::ConnectionKind::kStrobe)) {
    d.choices |= alloc::kBitStrobe;
    d.strobe_input = fitting(io.input(strobe->input));
  }
  return d;
}

ConnectionSetOptions EdsSlave::connection_options(const EdsSlaveOptions& o,
                                                  const IoDefaults& d) noexcept {
  ConnectionSetOptions c;
  c.supported_choices = d.choices;
  c.timer_resolution = o.timer_resolution;
  c.poll_produced_assembly = d.poll_input;
  c.poll_consumed_assembly = d.poll_output;
  c.cos_produced_assembly = d.cos_input;
  c.strobe_produced_assembly = d.strobe_input;
  return c;
}

EdsSlave::EdsSlave(can::FrameSink& sink, profiles::eds::EdsFile file, EdsSlaveOptions options,
                   Logger log)
    : Group2Slave(sink, wire_options(file, options), std::move(log)),
      options_(options),
      objects_(std::move(file), options.serial_number, options.member_lists),
      mac_(MacId::from_bits(options.mac)),
      defaults_(io_defaults(objects_)),
      connections_(connection_options(options_, defaults_), *this) {
  if (auto n = safe_state_params(objects_.file())) {
    safe_state_params_ = SafeStateParams{(*n)[0], (*n)[1], (*n)[2], (*n)[3]};
  }
}

void EdsSlave::power_up_device(TimePoint, PowerUpCause) noexcept {
  connections_.drop();
  end_cos();
  objects_.ack_handler().cos_acknowledged = false;
  if (defaults_.poll_output != 0) {
    const std::vector<std::uint8_t> zero(objects_.assembly_data(defaults_.poll_output).size(), 0);
    (void)objects_.set_assembly_data(defaults_.poll_output, Bytes(zero.data(), zero.size()));
  }
}

// --- time and production -----------------------------------------------------

void EdsSlave::device_timer(TimePoint now) noexcept {
  connections_.on_timer(now);
  if (cos_ && now >= cos_->next_deadline()) produce(cos_->on_timer(now), now);
}

TimePoint EdsSlave::device_deadline() const noexcept {
  return std::min(connections_.next_deadline(), cos_ ? cos_->next_deadline() : kNever);
}

void EdsSlave::inputs_changed(TimePoint now) noexcept {
  if (!cos_ || network_state() != NetworkState::kOnline) return;
  const auto data = objects_.assembly_data(connections_.cos_connection().produced_assembly);
  produce(cos_->set_data(Bytes(data.data(), data.size()), now), now);
}

void EdsSlave::produce(const std::optional<std::vector<std::uint8_t>>& message,
                       TimePoint now) noexcept {
  if (!message) return;
  send(devicenet::group1_id(Group1Message::kSlaveCosCyclic, mac_),
       Bytes(message->data(), std::min(message->size(), kMaxPollData)), now);
}

bool EdsSlave::on_io_message(Group2Message message, const can::CanFrame& frame,
                             TimePoint now) noexcept {
  if (message == Group2Message::kMasterBitStrobeCommand) return on_strobe(frame, now);
  if (message != Group2Message::kMasterCosCyclicAck || !cos_ ||
      objects_.ack_handler().cos_producing_instance != connection_instance::kChangeOfState) {
    return false;
  }
  cos_->on_ack();
  connections_.consumed(connection_instance::kChangeOfState, now);
  return true;
}

bool EdsSlave::on_strobe(const can::CanFrame& frame, TimePoint now) noexcept {
  const Connection& c = connections_.strobe_connection();
  if (c.state != ConnectionState::kEstablished) return false;
  connections_.consumed(connection_instance::kBitStrobe, now);
  ++strobe_counters_.commands;
  // The device's bit of the bitmap; a shorter command leaves it clear.
  const unsigned bit = mac_.value();
  strobe_counters_.last_bit = frame.len > bit / 8 && ((frame.data[bit / 8] >> (bit % 8)) & 1) != 0;
  const auto data = objects_.assembly_data(c.produced_assembly);
  send(devicenet::group1_id(Group1Message::kSlaveBitStrobeResponse, mac_),
       Bytes(data.data(), std::min(data.size(), kMaxPollData)), now);
  ++strobe_counters_.responses;
  return true;
}

CosProducerCounters EdsSlave::cos_counters() const noexcept {
  CosProducerCounters c = cos_ended_;
  if (cos_) c += cos_->counters();
  return c;
}

void EdsSlave::end_cos() noexcept {
  if (!cos_) return;
  cos_ended_ += cos_->counters();
  cos_.reset();
}

// --- the I/O connections' changes ------------------------------------------------

void EdsSlave::on_io_established(std::uint16_t instance, TimePoint now) noexcept {
  if (instance == connection_instance::kChangeOfState) start_cos(now);
}

void EdsSlave::on_io_rate_changed(std::uint16_t instance, TimePoint) noexcept {
  if (instance != connection_instance::kChangeOfState || !cos_) return;
  cos_->set_expected_packet_rate(
      milliseconds(connections_.cos_connection().expected_packet_rate_ms));
}

void EdsSlave::on_io_released(std::uint16_t instance, const Connection& before,
                              TimePoint) noexcept {
  if (instance == connection_instance::kChangeOfState) {
    end_cos();
    objects_.ack_handler().cos_acknowledged = false;
    return;
  }
  // The outputs of the assembly the released connection consumed, which
  // its consumed path may have named (attribute 16).
  if (before.state == ConnectionState::kEstablished) {
    apply_output_action(false, before.consumed_assembly);
  }
}

void EdsSlave::on_io_timed_out(std::uint16_t instance, const Connection& before,
                               TimePoint) noexcept {
  if (instance == connection_instance::kChangeOfState) {
    // Auto Reset leaves it Established: it goes on producing.
    if (!connections_.established(instance)) {
      end_cos();
      objects_.ack_handler().cos_acknowledged = false;
    }
    return;
  }
  apply_output_action(true, before.consumed_assembly);
}

void EdsSlave::start_cos(TimePoint now) noexcept {
  const Connection& c = connections_.cos_connection();
  const AckHandler& ack = objects_.ack_handler();
  CosProduction p;
  p.expected_packet_rate = milliseconds(c.expected_packet_rate_ms);
  p.inhibit = milliseconds(c.inhibit_ms);
  p.cyclic = (c.allocated_as & alloc::kCyclic) != 0;
  p.ack_suppressed = (c.allocated_as & alloc::kAckSuppression) != 0;
  p.ack_timer = milliseconds(ack.ack_timer_ms);
  p.retry_limit = ack.retry_limit;
  const auto data = objects_.assembly_data(c.produced_assembly);
  end_cos();
  cos_.emplace(p, Bytes(data.data(), data.size()), now);
  objects_.ack_handler().cos_acknowledged = !p.ack_suppressed;
}

void EdsSlave::go_offline(TimePoint) noexcept {
  if (connections_.established(connection_instance::kPoll)) {
    apply_output_action(true, connections_.poll_connection().consumed_assembly);
  }
  connections_.drop();
  end_cos();
}

void EdsSlave::apply_output_action(bool fault, std::uint16_t outputs) noexcept {
  if (outputs == 0) return;
  std::vector<std::uint8_t> data(objects_.assembly_data(outputs).size(), 0);
  if (safe_state_params_) {
    const SafeStateParams& p = *safe_state_params_;
    const auto action = objects_.param_number(fault ? p.fault_action : p.idle_action);
    if (action && *action != 0) return;  // hold
    const auto value = objects_.param_value(fault ? p.fault_value : p.idle_value);
    std::copy_n(value.begin(), std::min(value.size(), data.size()), data.begin());
  } else if ((fault ? options_.fault_action : options_.idle_action) == OutputAction::kHold) {
    return;
  }
  (void)objects_.set_assembly_data(outputs, Bytes(data.data(), data.size()));
}

// --- poll --------------------------------------------------------------------------

PollResult EdsSlave::poll(Bytes command, TimePoint now) noexcept {
  PollResult result;
  const Connection& c = connections_.poll_connection();
  if (c.state != ConnectionState::kEstablished) return result;
  const std::uint16_t consumed = connection_size(connection_instance::kPoll, false);
  if (command.size() > consumed) {
    result.outcome = PollOutcome::kOversize;
    return result;
  }
  connections_.consumed(connection_instance::kPoll, now);
  // Shorter than the consumed size: the idle condition; a connection that
  // consumes nothing has none (bridge/PROTOCOL.md §7).
  const bool idle = command.size() < consumed;
  if (idle) {
    result.outcome = PollOutcome::kIdle;
    apply_output_action(false, c.consumed_assembly);
  } else {
    result.outcome = PollOutcome::kApplied;
    if (consumed > 0 && !objects_.set_assembly_data(c.consumed_assembly, command)) {
      result.outcome = PollOutcome::kInvalid;
    }
  }
  if (!(idle && options_.idle_poll_answered_empty)) {
    const auto data = objects_.assembly_data(c.produced_assembly);
    (void)result.response.assign(Bytes(data.data(), std::min(data.size(), kMaxPollData)));
  }
  return result;
}

std::uint16_t EdsSlave::connection_size(std::uint16_t instance, bool produced) const noexcept {
  if (instance == connection_instance::kExplicit) return kExplicitMessageSize;
  const Connection* c = connections_.connection(instance);
  if (c == nullptr) return 0;
  if (instance == connection_instance::kBitStrobe && !produced) {
    return c->state == ConnectionState::kNonExistent ? 0 : kStrobeCommandSize;
  }
  const std::uint16_t assembly = produced ? c->produced_assembly : c->consumed_assembly;
  if (assembly == 0) return 0;
  return static_cast<std::uint16_t>(objects_.assembly_data(assembly).size());
}

bool EdsSlave::assembly_allowed(std::uint16_t instance, bool produced,
                                std::uint16_t assembly) const noexcept {
  if (instance == connection_instance::kExplicit) return false;
  if (!produced) {
    // The change-of-state connection consumes acknowledgments and the
    // bit-strobe connection the command's bitmap, no data; a poll command
    // goes into an output assembly, never into the inputs' parameters.
    if (instance == connection_instance::kChangeOfState ||
        instance == connection_instance::kBitStrobe || !is_output_assembly(assembly)) {
      return false;
    }
  } else if (!input_carried_by(assembly, instance)) {
    return false;
  }
  return fits_one_frame(objects_.assembly_data(assembly).size());
}

bool EdsSlave::input_carried_by(std::uint16_t assembly, std::uint16_t instance) const noexcept {
  // An [IO_Info] input names the connections that may carry it; an
  // assembly no input names (an output's echo) is not checked.
  const profiles::eds::EdsFile& file = objects_.file();
  for (const profiles::eds::IoData& in : file.io.inputs) {
    if (io_assembly(file, &in) != assembly || in.carried_by.bits == 0) continue;
    switch (instance) {
      case connection_instance::kPoll:
        return in.carried_by.has(profiles::eds::ConnectionKind::kPoll);
      case connection_instance::kBitStrobe:
        return in.carried_by.has(profiles::eds::ConnectionKind::kStrobe);
      case connection_instance::kChangeOfState:
        return in.carried_by.has(profiles::eds::ConnectionKind::kChangeOfState) ||
               in.carried_by.has(profiles::eds::ConnectionKind::kCyclic);
      default:
        return false;
    }
  }
  return true;
}

bool EdsSlave::is_output_assembly(std::uint16_t assembly) const noexcept {
  const profiles::eds::EdsFile& file = objects_.file();
  return std::any_of(
      file.io.outputs.begin(), file.io.outputs.end(),
      [&](const profiles::eds::IoData& out) { return io_assembly(file, &out) == assembly; });
}

// --- explicit requests -------------------------------------------------------------

std::size_t EdsSlave::execute(const devicenet::RequestMessage& request, std::uint8_t requester,
                              TimePoint now, MutableBytes out) noexcept {
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> data{};
  ByteWriter w{MutableBytes(data)};
  switch (request.class_id) {
    case devicenet::kDeviceNetClass:
      return encode_reply(request.service, devicenet_object(request, requester, now, w), w, out);
    case cip::class_id::kConnection:
      return encode_reply(request.service, connection_object(request, now, w), w, out);
    default: {
      const std::size_t n = objects_.execute(request, out);
      // A Set may have changed what the change-of-state connection produces.
      inputs_changed(now);
      return n;
    }
  }
}

// The checks in the order the other objects make them (eds_objects.hpp):
// instance, service, attribute, data with a Get, attribute supported,
// settable.
Reply EdsSlave::devicenet_object(const devicenet::RequestMessage& r, std::uint8_t requester,
                                 TimePoint now, ByteWriter& w) noexcept {
  if (r.instance_id > 1) return reply_error(GeneralStatus::kObjectDoesNotExist);
  const auto service = static_cast<cip::Service>(r.service);
  if (r.instance_id == 1 && service == cip::Service::kAllocateMasterSlave) {
    return allocate_service(connections_, r.data, now, w);
  }
  if (r.instance_id == 1 && service == cip::Service::kReleaseMasterSlave) {
    return release_service(connections_, r.data, requester, now);
  }
  const bool get = service == cip::Service::kGetAttributeSingle;
  if (!get && !(service == cip::Service::kSetAttributeSingle && r.instance_id == 1)) {
    return reply_error(GeneralStatus::kServiceNotSupported);
  }
  if (!r.attribute) return reply_error(GeneralStatus::kNotEnoughData);
  if (get && !r.data.empty()) return reply_error(GeneralStatus::kTooMuchData);
  const std::uint8_t a = *r.attribute;
  if (r.instance_id == 0) {
    if (a != cip::class_attr::kRevision) return reply_error(GeneralStatus::kAttributeNotSupported);
    return put_u16(w, 2);
  }
  if (a != 1 && a != 2 && a != 5) return reply_error(GeneralStatus::kAttributeNotSupported);
  // The MAC and baud rate are the switches' here.
  if (!get) return reply_error(GeneralStatus::kAttributeNotSettable);
  if (a == 1) return put_u8(w, mac_.value());
  if (a == 2) return put_u8(w, options_.baud);
  return put_allocation_information(connections_, w);
}

Reply EdsSlave::connection_object(const devicenet::RequestMessage& r, TimePoint now,
                                  ByteWriter& w) noexcept {
  const bool class_level = r.instance_id == 0;
  if (!class_level && !connections_.exists(r.instance_id)) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  const auto service = static_cast<cip::Service>(r.service);
  if (service == cip::Service::kReset) {
    return class_level ? reset_connection_class(connections_, r.data, now)
                       : reset_connection(connections_, r.instance_id, r.data, now);
  }
  const bool get = service == cip::Service::kGetAttributeSingle;
  if (!get && !(service == cip::Service::kSetAttributeSingle && !class_level)) {
    return reply_error(GeneralStatus::kServiceNotSupported);
  }
  if (!r.attribute) return reply_error(GeneralStatus::kNotEnoughData);
  if (get && !r.data.empty()) return reply_error(GeneralStatus::kTooMuchData);
  const std::uint8_t a = *r.attribute;
  if (class_level) {
    if (a != cip::class_attr::kRevision) return reply_error(GeneralStatus::kAttributeNotSupported);
    return put_u16(w, 1);
  }
  if (!connection_attribute_exists(a)) return reply_error(GeneralStatus::kAttributeNotSupported);
  if (get) return get_connection_attribute(connections_, mac_, *this, r.instance_id, a, w);
  if (!connection_attribute_settable(r.instance_id, a)) {
    return reply_error(GeneralStatus::kAttributeNotSettable);
  }
  return set_connection_attribute(connections_, *this, r.instance_id, a, r.data, now, w);
}

// The MAC is the switches' (DeviceNet object attribute 1 is Get here): the
// offline set cannot change it.
Reply EdsSlave::set_mac(std::uint8_t) noexcept {
  return reply_error(GeneralStatus::kAttributeNotSettable);
}

}  // namespace dnbridge::sim
