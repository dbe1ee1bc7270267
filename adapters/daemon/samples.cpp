#include "adapters/daemon/samples.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/states.hpp"
#include "bridge/cip/data_types.hpp"

namespace dnbridge::daemon {

namespace cdn127 = profiles::cdn127;
using dds::set_octets;
using dds::set_string;
using dds::to_idl;

std::string_view device_state_text(std::uint8_t state) {
  // CDN127 manual, Identity object, "Device State - Attribute 8".
  switch (state) {
    case 0:
      return "non-existent";
    case 1:
      return "self test";
    case 2:
      return "standby";
    case 3:
      return "operating";
    case 4:
      return "major recoverable fault";
    case 5:
      return "major unrecoverable fault";
    default:
      return "reserved";
  }
}

void fill_pump_state(dnbridge_PumpState& out, std::string_view rack, std::string_view port,
                     const rack::PumpView& v) {
  set_string(out.rack, rack);
  set_string(out.port, port);
  out.mac = v.mac.value();
  set_string(out.name, v.name);
  out.online = v.online;

  const bool inputs = v.online && v.has_inputs;
  out.inputs_valid = inputs && v.inputs.pump.has_value();
  const cdn127::PumpInputs pump =
      inputs ? v.inputs.pump.value_or(cdn127::PumpInputs{}) : cdn127::PumpInputs{};
  out.pump_running = out.inputs_valid && pump.pump_running;
  out.warning_active = out.inputs_valid && pump.warning_active;
  out.alarm_active = out.inputs_valid && pump.alarm_active;
  out.n2_flow_ok = out.inputs_valid && pump.n2_flow_ok;
  out.interlock_ok = out.inputs_valid && pump.interlock_ok;
  out.digital_inputs_raw = inputs ? v.inputs.input_bits.value_or(0) : 0;

  const auto exception =
      inputs ? v.inputs.exception_status : std::optional<cdn127::ExceptionStatus>{};
  out.exception_status_valid = exception.has_value();
  const cdn127::ExceptionStatus e = exception.value_or(cdn127::ExceptionStatus{});
  out.alarm_device_common = e.alarm_device_common;
  out.alarm_device_specific = e.alarm_device_specific;
  out.alarm_manufacturer_specific = e.alarm_manufacturer_specific;
  out.warning_device_common = e.warning_device_common;
  out.warning_device_specific = e.warning_device_specific;
  out.warning_manufacturer_specific = e.warning_manufacturer_specific;

  out.analog_input_count = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto raw = inputs ? v.inputs.analog_inputs_raw[i] : std::optional<std::uint16_t>{};
    const bool valid = raw && v.inputs.analog_input_in_range[i];
    out.analog_input_raw[i] = raw.value_or(0);
    out.analog_input_volts[i] = valid ? static_cast<float>(cdn127::raw_to_volts(*raw))
                                : raw ? std::numeric_limits<float>::quiet_NaN()
                                      : 0.0F;
    out.analog_input_valid[i] = valid;
    if (raw) out.analog_input_count = static_cast<std::uint8_t>(i + 1);
  }

  out.outputs_idle = v.outputs_idle;
  const cdn127::PumpOutputs applied = v.outputs_idle ? cdn127::PumpOutputs{} : v.outputs_applied;
  out.pump_on = applied.pump_on;
  out.n2_ballast_on = applied.n2_ballast_on;
  out.analog_output_raw = applied.analog_out_raw;
  out.analog_output_volts = static_cast<float>(cdn127::raw_to_volts(applied.analog_out_raw));
  set_string(out.commanded_by,
             v.outputs_idle ? std::string_view{} : std::string_view(v.commanded_by));
  set_string(out.idle_reason, v.idle_reason());
}

namespace {

void fill_safe_state(dnbridge_NodeStatus& out, const rack::PumpView& v) {
  out.safe_state_known = v.safe_state.has_value();
  out.safe_state_source = v.safe_state_source == cdn127::SafeStateSource::kDevice
                              ? dnbridge_SAFE_STATE_DEVICE
                              : dnbridge_SAFE_STATE_CONFIGURED;
  const auto unknown = dnbridge_SAFE_ACTION_UNKNOWN;
  const auto& s = v.safe_state;
  out.pump_on_fault = s ? to_idl(s->pump_fault) : unknown;
  out.pump_on_idle = s ? to_idl(s->pump_idle) : unknown;
  out.n2_ballast_on_fault = s ? to_idl(s->n2_ballast_fault) : unknown;
  out.n2_ballast_on_idle = s ? to_idl(s->n2_ballast_idle) : unknown;
  out.analog_output_on_fault = s ? to_idl(s->analog_fault) : unknown;
  out.analog_output_fault_raw = s ? s->analog_fault.raw : 0;
  out.analog_output_on_idle = s ? to_idl(s->analog_idle) : unknown;
  out.analog_output_idle_raw = s ? s->analog_idle.raw : 0;
  set_string(out.safe_state_text,
             s ? std::string_view(v.safe_state_text) : std::string_view{"not read yet"});
}

}  // namespace

// What NodeStatus says of any node, whatever its profile.
void fill_node_common(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::NodeView& v, const port::NodeStatusView& node) {
  set_string(out.rack, rack);
  set_string(out.port, port);
  out.mac = v.mac.value();
  set_string(out.name, v.name);
  out.state = to_idl(node.state);
  set_string(out.reason, node.reason);
  out.command_refresh_ms = static_cast<std::uint32_t>(
      std::chrono::duration_cast<milliseconds>(v.command_refresh).count());

  const auto& id = node.identity;
  out.vendor_id = id.vendor_id;
  out.product_type = id.product_type;
  out.product_code = id.product_code;
  out.major_revision = id.major_revision;
  out.minor_revision = id.minor_revision;
  out.serial_number = id.serial_number;
  set_string(out.product_name, cip::utf8_from_iso8859_1(id.product_name));
  out.device_state_valid = node.device_state.has_value();
  out.device_state = node.device_state.value_or(0);
  // Identity.State is optional: a device read at start-up (its status
  // answered) that has none is in a state unknown, not at fault.
  set_string(out.device_state_text, node.device_state ? device_state_text(*node.device_state)
                                    : node.identity.status
                                        ? std::string_view{"state unknown (no Identity.State)"}
                                        : std::string_view{});

  const auto ms = [](Duration d) {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<milliseconds>(d).count());
  };
  out.poll_period_ms = ms(node.poll_period);
  out.expected_packet_rate_ms = ms(node.poll_epr);
  out.produced_size = static_cast<std::uint16_t>(node.produced_size);
  out.consumed_size = static_cast<std::uint16_t>(node.consumed_size);

  const auto& error = node.last_error;
  set_string(out.last_error,
             error.kind == devicenet::NodeError::Kind::kNone ? std::string{} : error.describe());
  out.last_error_general_status = static_cast<std::uint8_t>(error.general_status);
  out.last_error_additional_status = error.additional_status;
  set_string(out.last_command_refused, v.last_command_refused);
  set_string(out.invalid_inputs,
             v.online && v.inputs_withheld_when_idle
                 ? std::string_view{"no inputs while idle: the device answers idle polls without "
                                    "data"}
                 : std::string_view{});
  set_string(out.device_faults, v.minor_faults);

  const auto& c = node.counters;
  const auto& e = node.explicit_counters;
  out.counters.polls = c.polls;
  out.counters.idle_polls = c.idle_polls;
  out.counters.poll_responses = c.responses;
  out.counters.poll_timeouts = c.timeouts;
  out.counters.poll_retries = c.retries;
  out.counters.poll_errors = c.errors;
  out.counters.reconnects = c.reconnects;
  out.counters.allocate_attempts = c.allocate_attempts;
  out.counters.idle_empty_responses = c.idle_empty_responses;
  out.counters.settings_written = c.settings_written;
  out.counters.cos_messages = c.cos_messages;
  out.counters.cos_acks = c.cos_acks;
  out.counters.cos_retries = c.cos_retries;
  out.counters.cos_errors = c.cos_errors;
  out.counters.heartbeats_missed = c.heartbeats_missed;
  out.counters.explicit_retries = c.explicit_retries;
  out.counters.explicit_responses_before_final_ack = e.responses_before_final_ack;
  out.counters.explicit_requests = e.requests;
  out.counters.explicit_timeouts = e.timeouts;
  out.counters.explicit_device_errors = e.device_errors;
  out.counters.commands_accepted = v.commands_accepted;
  out.counters.commands_refused = v.commands_refused;
}

void fill_node_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::PumpView& v, const port::NodeStatusView& node) {
  fill_node_common(out, rack, port, v, node);
  std::string invalid(dds::view(out.invalid_inputs));
  for (std::size_t i = 0; i < v.inputs.analog_inputs_raw.size(); ++i) {
    const auto& raw = v.inputs.analog_inputs_raw[i];
    if (!v.has_inputs || !raw || v.inputs.analog_input_in_range[i]) continue;
    if (!invalid.empty()) invalid += "; ";
    invalid +=
        fmt::format("analog input {}: {} counts, above {}", i + 1, *raw, cdn127::kAnalogMaxRaw);
  }
  set_string(out.invalid_inputs, invalid);
  fill_safe_state(out, v);
  set_string(out.idle_reason, v.idle_reason());
  out.counters.responses_with_invalid_inputs = v.responses_with_invalid_inputs;
}

void fill_node_status(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const rack::DeviceView& v, const port::NodeStatusView& node) {
  fill_node_common(out, rack, port, v, node);
  // Its safe state is the EDS parameters the configuration gives, or the
  // device's own (safe_state = "device"): no CDN127 action to name, the
  // values read back in words.
  const auto unknown = dnbridge_SAFE_ACTION_UNKNOWN;
  out.safe_state_known = v.safe_state_read;
  out.safe_state_source =
      v.safe_state_of_device ? dnbridge_SAFE_STATE_DEVICE : dnbridge_SAFE_STATE_CONFIGURED;
  out.pump_on_fault = out.pump_on_idle = out.n2_ballast_on_fault = out.n2_ballast_on_idle =
      out.analog_output_on_fault = out.analog_output_on_idle = unknown;
  out.analog_output_fault_raw = out.analog_output_idle_raw = 0;
  set_string(out.safe_state_text, v.safe_state_text.empty() ? std::string_view{"not read yet"}
                                                            : std::string_view(v.safe_state_text));
  set_string(out.idle_reason, v.idle_reason());
}

namespace {

// A sequence of fields the sample owns (freed with it).
void set_fields(dds_sequence_dnbridge_DeviceField& seq, const profiles::eds::IoLayout& layout,
                const std::vector<profiles::eds::FieldValue>& values) {
  seq._length = seq._maximum = static_cast<std::uint32_t>(values.size());
  seq._release = true;
  seq._buffer =
      values.empty() ? nullptr : dds_sequence_dnbridge_DeviceField_allocbuf(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const profiles::eds::FieldValue& v = values[i];
    const profiles::eds::IoField& f = layout.fields[v.field];
    auto& o = seq._buffer[i];
    set_string(o.name, f.name);
    o.param = f.param;
    set_string(o.type, f.type.name);
    set_string(o.units, f.units);
    o.bit_offset = f.offset;
    o.bits = f.bits;
    o.value = v.value;
    o.shown = v.shown;
  }
}

}  // namespace

void fill_device_state(dnbridge_DeviceState& out, std::string_view rack, std::string_view port,
                       const rack::DeviceView& v) {
  set_string(out.rack, rack);
  set_string(out.port, port);
  out.mac = v.mac.value();
  set_string(out.name, v.name);
  set_string(out.product, cip::utf8_from_iso8859_1(v.product));
  out.online = v.online;
  out.inputs_valid = v.online && v.has_inputs;
  const std::vector<profiles::eds::FieldValue> none;
  set_octets(out.inputs, out.inputs_valid ? std::span<const std::uint8_t>(v.inputs)
                                          : std::span<const std::uint8_t>{});
  set_fields(out.input_fields, v.io->produced, out.inputs_valid ? v.input_values : none);
  out.outputs_idle = v.outputs_idle;
  set_string(out.idle_reason, v.idle_reason());
  set_octets(out.outputs, v.outputs_idle ? std::span<const std::uint8_t>{}
                                         : std::span<const std::uint8_t>(v.outputs_applied));
  set_fields(out.output_fields, v.io->consumed, v.outputs_idle ? none : v.output_values);
  set_string(out.commanded_by,
             v.outputs_idle ? std::string_view{} : std::string_view(v.commanded_by));
}

void fill_port_status(dnbridge_PortStatus& out, std::string_view rack,
                      const port::PortStatusView& s) {
  set_string(out.rack, rack);
  set_string(out.port, s.port);
  set_string(out.can_interface, s.interface_name);
  out.bitrate = s.bitrate;
  out.master_mac = s.master_mac.value();
  out.state = to_idl(s.state);
  set_string(out.reason, s.reason);
  out.bus_state = to_idl(s.bus.state);
  out.tx_error_counter = s.bus.tx_errors;
  out.rx_error_counter = s.bus.rx_errors;
  out.frames_per_second = static_cast<float>(s.frames_per_second);
  out.bus_load_percent = static_cast<float>(s.bus_load_percent);
  out.scan_cycle_ms = static_cast<float>(s.scan_cycle_ms);
  out.nodes_online = s.nodes_online;
  out.nodes_configured = s.nodes_configured;
  out.explicit_outstanding = s.explicit_outstanding;
  out.explicit_retained = s.explicit_retained;
  out.explicit_refused_for_limits = s.explicit_refused_for_limits;
  out.loop_longest_pass_ms = static_cast<float>(s.loop_longest_pass_ms);
  dds::set_octets(out.unconfigured_macs, s.unconfigured_macs);
}

void fill_explicit_reply(dnbridge_ExplicitReply& out, const rack::ExplicitAnswer& a) {
  set_string(out.requester, a.requester);
  out.txid = a.txid;
  out.status = static_cast<std::uint8_t>(a.status);
  out.general_status = a.general_status;
  out.additional_status = a.additional_status;
  set_octets(out.data, a.data);
  set_string(out.message, a.message);
}

void fill_bus_scan_reply(dnbridge_BusScanReply& out, std::string_view rack, std::string_view port,
                         const port::BusScanAnswer& a) {
  set_string(out.requester, a.requester);
  out.txid = a.txid;
  set_string(out.rack, rack);
  set_string(out.port, port);
  out.status = static_cast<std::uint8_t>(a.status);
  set_string(out.message, a.message);
  const auto ms = [](Duration d) {
    const auto n = std::chrono::duration_cast<milliseconds>(d).count();
    return static_cast<std::uint32_t>(
        std::clamp<std::int64_t>(n, 0, std::numeric_limits<std::uint32_t>::max()));
  };
  out.duration_ms = ms(a.duration);
  out.age_ms = ms(a.age);
  // The sample owns its findings (freed with it): allocated as a DDS buffer.
  auto& seq = out.findings;
  seq._length = seq._maximum = static_cast<std::uint32_t>(a.findings.size());
  seq._release = true;
  seq._buffer =
      a.findings.empty() ? nullptr : dds_sequence_dnbridge_ScanFinding_allocbuf(a.findings.size());
  for (std::size_t i = 0; i < a.findings.size(); ++i) {
    const auto& f = a.findings[i];
    auto& o = seq._buffer[i];
    o.mac = f.mac.value();
    o.found = dds::found_to_idl(f.outcome);
    o.vendor_id = f.identity.vendor_id;
    o.product_type = f.identity.product_type;
    o.product_code = f.identity.product_code;
    o.major_revision = f.identity.major_revision;
    o.minor_revision = f.identity.minor_revision;
    o.serial_number = f.identity.serial_number;
    set_string(o.product_name, f.identity.product_name);
    set_string(o.detail, f.detail);
  }
}

namespace {

// A sequence of strings the sample owns (freed with it).
void set_strings(dds_sequence_string& seq, const std::vector<std::string>& lines) {
  seq._length = seq._maximum = static_cast<std::uint32_t>(lines.size());
  seq._release = true;
  seq._buffer = lines.empty() ? nullptr : dds_sequence_string_allocbuf(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    seq._buffer[i] = nullptr;
    set_string(seq._buffer[i], lines[i]);
  }
}

}  // namespace

void fill_reload_reply(dnbridge_ReloadReply& out, std::string_view rack, const ReloadCall& call,
                       const ReloadReport& r) {
  set_string(out.requester, call.requester);
  out.txid = call.txid;
  set_string(out.rack, rack);
  out.status = static_cast<std::uint8_t>(r.status);
  set_string(out.message, r.message);
  set_string(out.file, r.file);
  set_strings(out.applied, r.applied);
  set_strings(out.needs_restart, r.needs_restart);
  set_strings(out.problems, r.problems);
}

rack::NodeCommand command_of(const dnbridge_DeviceCommand& c) {
  const auto bytes = dds::view(c.outputs);
  if (!bytes.empty() && c.fields._length > 0) {
    return rack::NodeCommand(
        rack::MalformedCommand{"outputs and fields both given: a command gives one"});
  }
  if (!bytes.empty())
    return rack::NodeCommand(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
  std::vector<profiles::eds::FieldSetting> fields;
  const std::span<const dnbridge_DeviceFieldValue> given(c.fields._buffer, c.fields._length);
  for (const auto& f : given) fields.push_back({std::string(dds::view(f.name)), f.value});
  return rack::NodeCommand(std::move(fields));
}

rack::NodeCommand command_of(const dnbridge_PumpCommand& c) {
  cdn127::PumpOutputs o;
  o.pump_on = c.pump_on;
  o.n2_ballast_on = c.n2_ballast_on;
  o.analog_out_raw = c.analog_output_raw;  // checked by the rack model, never clipped
  return rack::NodeCommand(o);
}

rack::ExplicitCall call_of(const dnbridge_ExplicitRequest& r) {
  rack::ExplicitCall c;
  c.requester = std::string(dds::view(r.requester));
  c.txid = r.txid;
  c.command = r.command;
  c.port = std::string(dds::view(r.port));
  c.mac = r.mac;
  c.service = r.service;
  c.class_id = r.class_id;
  c.instance_id = r.instance_id;
  if (r.has_attribute) c.attribute = r.attribute_id;
  const auto data = dds::view(r.data);
  c.data.assign(data.begin(), data.end());
  return c;
}

}  // namespace dnbridge::daemon
