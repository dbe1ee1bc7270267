#include "adapters/sim/cdn127/cdn127_device.hpp"

#include <algorithm>
#include <utility>

#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::sim {

using cip::GeneralStatus;
using devicenet::MacId;
using profiles::cdn127::PollRequestLayout;
using profiles::cdn127::PollResponseLayout;
using profiles::cdn127::PumpOutputs;
namespace alloc = devicenet::allocation;

namespace {

ConnectionSetOptions connection_options(const SlaveOptions& o) noexcept {
  ConnectionSetOptions c;
  c.supported_choices = alloc::kExplicit | alloc::kPoll;
  c.timer_resolution = o.timer_resolution;
  c.explicit_timeout_action_settable = o.explicit_timeout_action_settable;
  c.poll_produced_assembly = profiles::cdn127::kDefaultProducedAssembly;
  c.poll_consumed_assembly = profiles::cdn127::kDefaultConsumedAssembly;
  return c;
}

E2Memory initial_e2(const SlaveOptions& o) noexcept {
  E2Memory e2;
  e2.configuration = o.configuration;
  e2.mac = o.stored_mac <= MacId::kMax ? o.stored_mac : MacId::kMax;
  e2.baud = o.stored_baud <= 2 ? o.stored_baud : 0;
  e2.dop = o.factory_output_actions.dop;
  e2.aop = o.factory_output_actions.aop;
  return e2;
}

std::uint16_t aop_action(std::uint8_t state, std::uint16_t value, std::uint16_t current) noexcept {
  switch (state) {
    case 1:
      return 0;
    case 2:
      return profiles::cdn127::kAnalogMaxRaw;
    case 3:
      return value;
    default:
      return current;  // 0: hold the last value
  }
}

}  // namespace

void apply_field_reading(SlaveOptions& o) {
  o.configuration_locked_while_poll_allocated = true;
  o.poll_paths_fixed = true;
  o.idle_poll_answered_empty = true;
  o.no_ack_of_last_request_fragment = true;
  o.release_keeps_outputs = true;
  o.explicit_response_delay = milliseconds(300);
  o.poll_response_delay = milliseconds(3);
  o.serial_number_udint = false;
  const ClassAttribute identity_state{profiles::cdn127::class_id::kIdentity, 8};
  if (std::find(o.unsupported_attributes.begin(), o.unsupported_attributes.end(), identity_state) ==
      o.unsupported_attributes.end()) {
    o.unsupported_attributes.push_back(identity_state);
  }
  o.timer_resolution = milliseconds(100);
}

Cdn127Device::Cdn127Device(const SlaveOptions& options) noexcept
    : options_(options),
      e2_(initial_e2(options)),
      pump_(options.pump),
      mac_switch_(options.mac_switch),
      baud_switch_(options.baud_switch),
      mac_switch_at_power_up_(options.mac_switch),
      baud_switch_at_power_up_(options.baud_switch),
      connections_(connection_options(options), *this) {}

void Cdn127Device::power_up(TimePoint now, PowerUpCause cause) noexcept {
  if (cause == PowerUpCause::kPowerOn) {
    faults_.major_unrecoverable = false;
    faults_.minor_unrecoverable = false;
  }
  // The switches are only read during power-up; a valid switch also becomes
  // the software setting ("defaults to the last hardware setting").
  mac_switch_at_power_up_ = mac_switch_;
  baud_switch_at_power_up_ = baud_switch_;
  if (!mac_switch_in_program_position()) e2_.mac = mac_switch_;
  if (!baud_switch_in_program_position()) e2_.baud = baud_switch_;
  mac_ = MacId::from_bits(e2_.mac);
  baud_ = e2_.baud;
  bus_off_counter_ = 0;
  connections_.drop();
  poll_running_ = false;
  pending_ = PendingAction::kNone;
  pump_.set_outputs(PumpOutputs{}, OutputCause::kPowerUp, now);
}

void Cdn127Device::restore_factory_defaults() noexcept { e2_ = initial_e2(options_); }

void Cdn127Device::set_switches(std::uint8_t mac_switch, std::uint8_t baud_switch) noexcept {
  mac_switch_ = mac_switch;
  baud_switch_ = baud_switch;
}

Reply Cdn127Device::set_mac(std::uint8_t mac) noexcept {
  // A valid switch setting governs the MAC; software setting needs the
  // program position (manual, DeviceNet object attribute 1).
  if (!mac_switch_in_program_position()) return reply_error(GeneralStatus::kAttributeNotSettable);
  if (mac > MacId::kMax) return reply_error(GeneralStatus::kInvalidAttributeValue);
  e2_.mac = mac;
  // The node leaves the network and comes back with its new MAC.
  if (mac != mac_.value()) pending_ = PendingAction::kRestart;
  return kReplyOk;
}

Reply Cdn127Device::set_baud(std::uint8_t baud) noexcept {
  if (!baud_switch_in_program_position()) return reply_error(GeneralStatus::kAttributeNotSettable);
  if (baud > 2) return reply_error(GeneralStatus::kInvalidAttributeValue);
  // Kept in E2, used from the next power-up (the bit rate cannot change under
  // a running network).
  e2_.baud = baud;
  return kReplyOk;
}

std::uint16_t Cdn127Device::connection_size(std::uint16_t instance, bool produced) const noexcept {
  if (instance == connection_instance::kExplicit) return kExplicitMessageSize;
  const Connection& poll = connections_.poll_connection();
  if (produced) {
    auto layout = profiles::cdn127::produced_assembly_layout(
        static_cast<std::uint8_t>(poll.produced_assembly), e2_.configuration);
    return layout.ok() ? static_cast<std::uint16_t>(layout->size) : 0;
  }
  auto layout = profiles::cdn127::consumed_assembly_layout(
      static_cast<std::uint8_t>(poll.consumed_assembly), e2_.configuration);
  return layout.ok() ? static_cast<std::uint16_t>(layout->size) : 0;
}

bool Cdn127Device::assembly_allowed(std::uint16_t instance, bool produced,
                                    std::uint16_t assembly) const noexcept {
  if (instance != connection_instance::kPoll) return false;
  return produced ? is_produced_assembly(assembly) : is_consumed_assembly(assembly);
}

void Cdn127Device::on_io_established(std::uint16_t, TimePoint) noexcept { poll_running_ = false; }

// A master that releases the poll connection has stopped the exchange on
// purpose: the outputs take their idle values, or, as the strict reading
// has it, stay as they are (the manual names no action for this case).
void Cdn127Device::on_io_released(std::uint16_t, const Connection& before, TimePoint now) noexcept {
  if (before.state == ConnectionState::kEstablished && !options_.release_keeps_outputs) {
    apply_idle_actions(now);
  }
  poll_running_ = false;
}

void Cdn127Device::on_io_timed_out(std::uint16_t, const Connection&, TimePoint now) noexcept {
  apply_fault_actions(now);
  poll_running_ = false;
}

std::size_t Cdn127Device::build_produced(const PollResponseLayout& layout, TimePoint now,
                                         MutableBytes out) noexcept {
  pump_.advance(now);
  const std::uint8_t bits = pump_.inputs().encode(e2_.configuration.no_nc_mask);
  auto size = profiles::cdn127::encode_poll_response(layout, exception_status_byte(), bits,
                                                     pump_.analog_inputs_raw(), out);
  if (!size.ok()) return 0;
  for (std::size_t i = 0; i < layout.ain_count && i < failed_analog_.size(); ++i) {
    if (!failed_analog_[i]) continue;
    const std::size_t at = layout.ain_offset + 2 * i;
    out[at] = static_cast<std::uint8_t>(*failed_analog_[i] & 0xFF);
    out[at + 1] = static_cast<std::uint8_t>(*failed_analog_[i] >> 8);
  }
  return *size;
}

PollResult Cdn127Device::on_poll(Bytes command, TimePoint now) noexcept {
  PollResult result;
  const Connection& poll = connections_.poll_connection();
  if (poll.state != ConnectionState::kEstablished) return result;
  auto request_layout = profiles::cdn127::consumed_assembly_layout(
      static_cast<std::uint8_t>(poll.consumed_assembly), e2_.configuration);
  auto response_layout = profiles::cdn127::produced_assembly_layout(
      static_cast<std::uint8_t>(poll.produced_assembly), e2_.configuration);
  if (!request_layout.ok() || !response_layout.ok()) return result;
  if (command.size() > request_layout->size) {
    result.outcome = PollOutcome::kOversize;
    return result;
  }
  connections_.consumed(connection_instance::kPoll, now);

  // A command shorter than the consumed size is the idle condition; with a
  // consumed size of 0 there is none (manual, "Poll Packet Sizes").
  const bool idle = command.size() < request_layout->size;
  result.outcome = idle ? PollOutcome::kIdle : PollOutcome::kApplied;
  PumpOutputs decoded{};
  if (!idle && request_layout->size > 0) {
    auto d = profiles::cdn127::decode_poll_request(*request_layout, command);
    if (d.ok()) {
      decoded = *d;
    } else {
      result.outcome = PollOutcome::kInvalid;
    }
  }
  // A major fault holds the outputs in their fault state (set_faults); the
  // master still gets the inputs.
  if (major_fault()) {
    result.outcome = PollOutcome::kMajorFault;
    poll_running_ = false;
  }
  auto apply = [&] {
    if (result.outcome == PollOutcome::kIdle) {
      apply_idle_actions(now);
      poll_running_ = false;
    } else if (result.outcome == PollOutcome::kApplied) {
      if (request_layout->size > 0)
        apply_decoded_outputs(*request_layout, decoded, OutputCause::kPoll, now);
      poll_running_ = true;
    }
  };
  // Mode NoPollUpdate: inputs are those sampled before the request, outputs
  // are updated after the response (manual, Mode Byte). Otherwise the I/O is
  // updated during poll processing, so the response sees the new outputs.
  const bool no_poll_update = (e2_.configuration.mode & profiles::cdn127::mode::kNoPollUpdate) != 0;
  // A device that answers the idle condition with no data.
  const bool answer_empty = idle && options_.idle_poll_answered_empty;
  if (!no_poll_update) apply();
  if (!answer_empty) {
    result.response.resize(build_produced(*response_layout, now, result.response.storage()));
  }
  if (no_poll_update) apply();
  return result;
}

std::size_t Cdn127Device::produced_data(std::uint8_t assembly, TimePoint now,
                                        MutableBytes out) noexcept {
  auto layout = profiles::cdn127::produced_assembly_layout(assembly, e2_.configuration);
  if (!layout.ok()) return 0;
  return build_produced(*layout, now, out);
}

std::size_t Cdn127Device::consumed_data(std::uint8_t assembly, MutableBytes out) const noexcept {
  auto layout = profiles::cdn127::consumed_assembly_layout(assembly, e2_.configuration);
  if (!layout.ok()) return 0;
  auto size = profiles::cdn127::encode_poll_request(*layout, pump_.outputs(), out);
  return size.ok() ? *size : 0;
}

Reply Cdn127Device::set_consumed_assembly(std::uint8_t assembly, Bytes data,
                                          TimePoint now) noexcept {
  auto layout = profiles::cdn127::consumed_assembly_layout(assembly, e2_.configuration);
  if (!layout.ok()) return reply_error(GeneralStatus::kAttributeNotSettable);
  if (data.size() < layout->size) return reply_error(GeneralStatus::kNotEnoughData);
  if (data.size() > layout->size) return reply_error(GeneralStatus::kTooMuchData);
  // The poll connection owns the assembly it consumes while it runs.
  if (connections_.established(connection_instance::kPoll) &&
      connections_.poll_connection().consumed_assembly == assembly) {
    return reply_error(GeneralStatus::kObjectStateConflict);
  }
  if (major_fault()) return reply_error(GeneralStatus::kDeviceStateConflict);
  if (layout->size == 0) return kReplyOk;
  auto decoded = profiles::cdn127::decode_poll_request(*layout, data);
  if (!decoded.ok()) return reply_error(GeneralStatus::kInvalidAttributeValue);
  apply_decoded_outputs(*layout, *decoded, OutputCause::kExplicit, now);
  return kReplyOk;
}

void Cdn127Device::apply_decoded_outputs(const PollRequestLayout& layout,
                                         const PumpOutputs& decoded, OutputCause cause,
                                         TimePoint now) noexcept {
  // Fields the layout does not carry keep their values.
  PumpOutputs next = pump_.outputs();
  if (layout.dout_size > 0) {
    next.pump_on = decoded.pump_on;
    next.n2_ballast_on = decoded.n2_ballast_on;
  }
  if (layout.aout_count > 0) next.analog_out_raw = decoded.analog_out_raw;
  pump_.set_outputs(next, cause, now);
}

Reply Cdn127Device::set_outputs(const PumpOutputs& outputs, OutputCause cause,
                                TimePoint now) noexcept {
  if (major_fault()) return reply_error(GeneralStatus::kDeviceStateConflict);
  pump_.set_outputs(outputs, cause, now);
  return kReplyOk;
}

void Cdn127Device::apply_fault_actions(TimePoint now) noexcept {
  PumpOutputs next = pump_.outputs();
  const auto& dop = e2_.dop;
  if (!dop[0].fault_hold) next.pump_on = dop[0].fault_value;
  if (!dop[1].fault_hold) next.n2_ballast_on = dop[1].fault_value;
  next.analog_out_raw = aop_action(e2_.aop.fault_state, e2_.aop.fault_value, next.analog_out_raw);
  pump_.set_outputs(next, OutputCause::kFault, now);
}

void Cdn127Device::apply_idle_actions(TimePoint now) noexcept {
  if (major_fault()) return;
  PumpOutputs next = pump_.outputs();
  const auto& dop = e2_.dop;
  if (!dop[0].idle_hold) next.pump_on = dop[0].idle_value;
  if (!dop[1].idle_hold) next.n2_ballast_on = dop[1].idle_value;
  next.analog_out_raw = aop_action(e2_.aop.idle_state, e2_.aop.idle_value, next.analog_out_raw);
  pump_.set_outputs(next, OutputCause::kIdle, now);
}

Reply Cdn127Device::set_configuration(const profiles::cdn127::IoConfiguration& config) noexcept {
  // "may only be set when the POLL connection is not in the RUNNING state":
  // Established, or, read strictly, allocated in any state.
  const bool locked = options_.configuration_locked_while_poll_allocated
                          ? connections_.exists(connection_instance::kPoll)
                          : connections_.established(connection_instance::kPoll);
  if (locked) return reply_error(GeneralStatus::kObjectStateConflict);
  // Mode bits 3..5 "should be set to 0"; counts within the device's maxima.
  if ((config.mode & 0x38) != 0 || !profiles::cdn127::validate(config).ok()) {
    return reply_error(GeneralStatus::kInvalidAttributeValue);
  }
  e2_.configuration = config;
  return kReplyOk;
}

std::uint16_t Cdn127Device::identity_status() const noexcept {
  std::uint16_t s = 0;
  if (owned()) s |= 0x0001;
  if (faults_.minor_recoverable) s |= 0x0100;
  if (faults_.minor_unrecoverable) s |= 0x0200;
  if (faults_.major_recoverable) s |= 0x0400;
  if (faults_.major_unrecoverable) s |= 0x0800;
  return s;
}

std::uint8_t Cdn127Device::identity_state() const noexcept {
  if (faults_.major_unrecoverable) return 5;
  if (faults_.major_recoverable) return 4;
  return 3;  // Operating
}

void Cdn127Device::set_faults(const IdentityFaults& faults, TimePoint now) noexcept {
  const bool was_major = major_fault();
  faults_ = faults;
  if (!was_major && major_fault()) {
    apply_fault_actions(now);
    poll_running_ = false;
  }
}

// The manual lists the values without saying when each is taken; ODVA's
// S-Device Supervisor stops in Abort on a recoverable fault and in Critical
// Fault on an unrecoverable one.
std::uint8_t Cdn127Device::supervisor_device_status() const noexcept {
  if (faults_.major_unrecoverable) return 6;  // Critical Fault
  if (faults_.major_recoverable) return 5;    // Abort
  if (connections_.established(connection_instance::kPoll) && poll_running_) {
    return 4;  // Executing
  }
  return 2;  // Idle
}

std::uint8_t Cdn127Device::exception_status_byte() noexcept {
  std::uint8_t b = pump_.exception_status(e2_.alarm_enable, e2_.warning_enable).encode();
  if (options_.report_expanded_mode) b |= 0x80;
  return b;
}

// Manufacturer detail bits (the manual's "See Below" never defines them):
// alarm bit 0 N2 flow failed, bit 1 pump alarm, bit 2 interlock failed;
// warning bit 0 pump warning.
std::uint8_t Cdn127Device::alarm_detail() const noexcept {
  if (!e2_.alarm_enable) return 0;
  std::uint8_t d = 0;
  if (!pump_.n2_flow_ok()) d |= 0x01;
  if (pump_.alarm_active()) d |= 0x02;
  if (!pump_.interlock_ok()) d |= 0x04;
  return d;
}

std::uint8_t Cdn127Device::warning_detail() const noexcept {
  return (e2_.warning_enable && pump_.warning_active()) ? 0x01 : 0x00;
}

PendingAction Cdn127Device::take_pending_action() noexcept {
  return std::exchange(pending_, PendingAction::kNone);
}

void Cdn127Device::go_offline(TimePoint now) noexcept {
  if (connections_.established(connection_instance::kPoll)) apply_fault_actions(now);
  connections_.drop();
  poll_running_ = false;
}

void Cdn127Device::on_timer(TimePoint now) noexcept {
  pump_.advance(now);
  connections_.on_timer(now);
}

TimePoint Cdn127Device::next_deadline() const noexcept {
  return std::min(pump_.next_deadline(), connections_.next_deadline());
}

}  // namespace dnbridge::sim
