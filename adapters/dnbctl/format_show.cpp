// show: a node's NodeStatus, with its PumpState or DeviceState when seen,
// as detail lines and as JSON.
#include <fmt/format.h>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/states.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/format_internal.hpp"

namespace dnbridge::dnbctl {

using dds::view;
using format_detail::pump_record;
using format_detail::yes_no;

namespace {

Record safe_state_record(const dnbridge_NodeStatus& s) {
  Record r;
  r.json("known", static_cast<bool>(s.safe_state_known))
      .json("source", s.safe_state_source == dnbridge_SAFE_STATE_DEVICE ? "device" : "configured")
      .json("pump_on_fault", dds::name_of(s.pump_on_fault))
      .json("pump_on_idle", dds::name_of(s.pump_on_idle))
      .json("n2_ballast_on_fault", dds::name_of(s.n2_ballast_on_fault))
      .json("n2_ballast_on_idle", dds::name_of(s.n2_ballast_on_idle))
      .json("analog_output_on_fault", dds::name_of(s.analog_output_on_fault))
      .json("analog_output_fault_raw", s.analog_output_fault_raw)
      .json("analog_output_on_idle", dds::name_of(s.analog_output_on_idle))
      .json("analog_output_idle_raw", s.analog_output_idle_raw)
      .json("text", view(s.safe_state_text));
  return r;
}

Record counters_record(const dnbridge_NodeCounters& c) {
  Record r;
  const auto counter = [&r](const char* label, const char* key, std::uint64_t v) {
    r.add(label, fmt::format("{}", v), key, v);
  };
  counter("polls", "polls", c.polls);
  counter("idle polls", "idle_polls", c.idle_polls);
  counter("poll responses", "poll_responses", c.poll_responses);
  counter("poll timeouts", "poll_timeouts", c.poll_timeouts);
  counter("poll retries", "poll_retries", c.poll_retries);
  counter("poll errors", "poll_errors", c.poll_errors);
  counter("reconnects", "reconnects", c.reconnects);
  counter("allocate attempts", "allocate_attempts", c.allocate_attempts);
  counter("idle empty responses", "idle_empty_responses", c.idle_empty_responses);
  counter("settings written", "settings_written", c.settings_written);
  counter("explicit requests", "explicit_requests", c.explicit_requests);
  counter("explicit retries", "explicit_retries", c.explicit_retries);
  counter("explicit timeouts", "explicit_timeouts", c.explicit_timeouts);
  counter("explicit device errors", "explicit_device_errors", c.explicit_device_errors);
  counter("last fragment unacked", "explicit_responses_before_final_ack",
          c.explicit_responses_before_final_ack);
  counter("invalid inputs", "responses_with_invalid_inputs", c.responses_with_invalid_inputs);
  counter("commands accepted", "commands_accepted", c.commands_accepted);
  counter("commands refused", "commands_refused", c.commands_refused);
  if (c.cos_messages != 0 || c.heartbeats_missed != 0) {
    // The input connection: change of state, cyclic or bit-strobe (the
    // reason says which); acks and retries are change of state's and cyclic's.
    counter("input messages", "cos_messages", c.cos_messages);
    counter("input acks", "cos_acks", c.cos_acks);
    counter("input retries", "cos_retries", c.cos_retries);
    counter("input errors", "cos_errors", c.cos_errors);
    counter("inputs lost (4 x EPR)", "heartbeats_missed", c.heartbeats_missed);
  }
  return r;
}

std::string none_if_empty(std::string_view s) { return s.empty() ? "none" : std::string(s); }

// A node as `show` shows it: its NodeStatus, with its PumpState if seen.
// A device's fields as they read: "Digital inputs = 165; Analog input 1 =
// -1000 mV" (with the EDS's scaling).
std::string fields_text(const dds_sequence_dnbridge_DeviceField& fields) {
  std::string text;
  for (std::uint32_t i = 0; i < fields._length; ++i) {
    const auto& f = fields._buffer[i];
    text += fmt::format("{}{} = {}{}{}", text.empty() ? "" : "; ", view(f.name), f.shown,
                        view(f.units).empty() ? "" : " ", view(f.units));
  }
  return text;
}

std::vector<Record> fields_records(const dds_sequence_dnbridge_DeviceField& fields) {
  std::vector<Record> out;
  for (std::uint32_t i = 0; i < fields._length; ++i) {
    const auto& f = fields._buffer[i];
    Record r;
    r.json("name", view(f.name))
        .json("type", view(f.type))
        .json("units", view(f.units))
        .json("bit_offset", f.bit_offset)
        .json("bits", f.bits)
        .json("value", f.value)
        .json("shown", f.shown);
    out.push_back(std::move(r));
  }
  return out;
}

// What DeviceState says of a device's data, for show.
void add_device_data(Record& r, const dnbridge_DeviceState& d) {
  const auto bytes = [](const dds_sequence_octet& seq) {
    return hex_bytes(std::span<const std::uint8_t>(dds::view(seq)));
  };
  r.add("product (EDS)", std::string(view(d.product)), "product", view(d.product));
  r.add("inputs",
        d.inputs_valid ? fmt::format("[{}] {}", bytes(d.inputs), fields_text(d.input_fields))
                       : std::string("not valid"),
        {{"inputs_valid", static_cast<bool>(d.inputs_valid)},
         {"inputs", bytes(d.inputs)},
         {"input_fields", Json::array(fields_records(d.input_fields))}});
  r.add("outputs",
        d.outputs_idle
            ? (view(d.idle_reason).empty() ? std::string("idle") : std::string(view(d.idle_reason)))
            : fmt::format("[{}] {}", bytes(d.outputs), fields_text(d.output_fields)),
        {{"outputs_idle", static_cast<bool>(d.outputs_idle)},
         {"outputs", bytes(d.outputs)},
         {"output_fields", Json::array(fields_records(d.output_fields))}});
  if (!d.outputs_idle) r.text("commanded by", std::string(view(d.commanded_by)));
}

Record node_record(const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump, bool alive,
                   const dnbridge_DeviceState* device) {
  Record identity;
  identity
      .add("vendor", fmt::format("{} (0x{:04X})", n.vendor_id, n.vendor_id), "vendor_id",
           n.vendor_id)
      .add("product type", fmt::format("{} (0x{:04X})", n.product_type, n.product_type),
           "product_type", n.product_type)
      .add("product code", fmt::format("{} (0x{:04X})", n.product_code, n.product_code),
           "product_code", n.product_code)
      .add("revision", fmt::format("{}.{}", n.major_revision, n.minor_revision),
           {{"major_revision", n.major_revision}, {"minor_revision", n.minor_revision}})
      .add("serial number", fmt::format("{} (0x{:08X})", n.serial_number, n.serial_number),
           "serial_number", n.serial_number)
      .add("product name", std::string(view(n.product_name)), "product_name", view(n.product_name));

  Json device_state;
  if (n.device_state_valid) {
    Record d;
    d.json("code", n.device_state).json("text", view(n.device_state_text));
    device_state = Json::object(std::move(d));
  }
  std::string outputs;
  if (pump && !pump->outputs_idle) {
    outputs = outputs_text(pump->pump_on, pump->n2_ballast_on, pump->analog_output_raw);
  } else if (pump) {
    outputs = view(pump->idle_reason).empty() ? "idle" : std::string(view(pump->idle_reason));
  }

  Record r;
  r.add("node", fmt::format("{} ({})", node_name(view(n.rack), view(n.port), n.mac), view(n.name)),
        {{"rack", view(n.rack)}, {"port", view(n.port)}, {"mac", n.mac}, {"name", view(n.name)}})
      .json("bridge_alive", alive)
      .add("state", fmt::format("{}{}", to_text(n.state), alive ? "" : " (bridge gone)"), "state",
           to_text(n.state))
      .add("reason", std::string(view(n.reason)), "reason", view(n.reason));
  if (pump) r.add("online", yes_no(alive && pump->online), "online", alive && pump->online);
  if (device) {
    r.add("online", yes_no(alive && device->online), "online", alive && device->online);
  }
  r.nest("identity", std::move(identity))
      .add("device state",
           n.device_state_valid ? fmt::format("{} ({})", n.device_state, view(n.device_state_text))
           : view(n.device_state_text).empty() ? std::string("not read")
                                               : std::string(view(n.device_state_text)),
           "device_state", std::move(device_state))
      .add("poll",
           fmt::format("every {} ms, {} byte(s) out, {} byte(s) in", n.poll_period_ms,
                       n.consumed_size, n.produced_size),
           {{"poll_period_ms", n.poll_period_ms},
            {"produced_size", n.produced_size},
            {"consumed_size", n.consumed_size}})
      .add("expected packet rate", fmt::format("{} ms", n.expected_packet_rate_ms),
           "expected_packet_rate_ms", n.expected_packet_rate_ms)
      .add(
          "last error",
          view(n.last_error).empty()
              ? std::string("none")
              : fmt::format("{} (general status 0x{:02X}, additional 0x{:02X})", view(n.last_error),
                            n.last_error_general_status, n.last_error_additional_status),
          {{"last_error", view(n.last_error)},
           {"last_error_general_status", n.last_error_general_status},
           {"last_error_additional_status", n.last_error_additional_status}})
      .add("command refresh",
           n.command_refresh_ms == 0
               ? std::string("off")
               : fmt::format("{} ms: a command not written again for this long is not in force",
                             n.command_refresh_ms),
           "command_refresh_ms", n.command_refresh_ms)
      .add("last refused command", none_if_empty(view(n.last_command_refused)),
           "last_command_refused", view(n.last_command_refused))
      .add("invalid inputs", none_if_empty(view(n.invalid_inputs)), "invalid_inputs",
           view(n.invalid_inputs));
  if (pump) {
    r.text("outputs", std::move(outputs));
    if (!pump->outputs_idle) r.text("commanded by", std::string(view(pump->commanded_by)));
  }
  if (device) add_device_data(r, *device);
  r.add("safe state",
        fmt::format("{} ({})", view(n.safe_state_text),
                    n.safe_state_source == dnbridge_SAFE_STATE_DEVICE
                        ? "the device's own, kept"
                        : "from the configuration, read back"),
        "safe_state", Json::object(safe_state_record(n)))
      .add("device faults", none_if_empty(view(n.device_faults)), "device_faults",
           view(n.device_faults))
      .json("idle_reason", view(n.idle_reason))
      .nest("counters", counters_record(n.counters), "counters");
  if (pump) r.json("pump", Json::object(pump_record(*pump)));
  return r;
}

// Labels are padded to this width in `show`.
constexpr std::size_t kDetailLabelWidth = 26;

}  // namespace

std::string node_details(const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump, bool alive,
                         const dnbridge_DeviceState* device) {
  return node_record(n, pump, alive, device).lines(kDetailLabelWidth);
}

void node_json(JsonWriter& out, const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump,
               bool alive, const dnbridge_DeviceState* device) {
  node_record(n, pump, alive, device).write(out);
}

}  // namespace dnbridge::dnbctl
