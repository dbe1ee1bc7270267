#include "adapters/dnbctl/format.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <tuple>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/states.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/rack/explicit_gateway.hpp"

namespace dnbridge::dnbctl {

using dds::view;

std::string_view to_text(dnbridge_NodeLifecycle state) { return dds::name_of(state); }
std::string_view to_text(dnbridge_PortLifecycle state) { return dds::name_of(state); }
std::string_view to_text(dnbridge_BusState state) { return dds::name_of(state); }

std::string transaction_status_text(std::uint8_t status) {
  // The bridge's own names (rack::TransactionStatus); 7 is unassigned.
  if (status >= 1 && status <= 15 && status != 7) {
    return std::string(rack::to_string(static_cast<rack::TransactionStatus>(status)));
  }
  return fmt::format("unknown status {}", status);
}

std::string general_status_text(std::uint8_t code) {
  if (cip::is_known(code)) return std::string(cip::to_string(static_cast<cip::GeneralStatus>(code)));
  if (code >= 0xD0) return fmt::format("object class specific (0x{:02X})", code);
  return fmt::format("reserved (0x{:02X})", code);
}

std::string service_text(std::uint8_t service) {
  const auto name = cip::to_string(static_cast<cip::Service>(service));
  if (!name.empty()) return std::string(name);
  return fmt::format("service 0x{:02X}", service);
}

std::string node_name(std::string_view rack, std::string_view port, unsigned mac) {
  return fmt::format("{}/{}/{}", rack, port, mac);
}

std::string Table::render() const {
  std::vector<std::size_t> width(headers_.size());
  for (std::size_t c = 0; c < headers_.size(); ++c) width[c] = headers_[c].size();
  for (const auto& row : rows_) {
    for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) {
      width[c] = std::max(width[c], row[c].size());
    }
  }
  std::string out;
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string l;
    for (std::size_t c = 0; c < cells.size() && c < width.size(); ++c) {
      if (c != 0) l += "  ";
      l += cells[c];
      if (c + 1 < cells.size()) l.append(width[c] - cells[c].size(), ' ');
    }
    while (!l.empty() && l.back() == ' ') l.pop_back();
    out += l;
    out += '\n';
  };
  line(headers_);
  for (const auto& row : rows_) line(row);
  return out;
}

namespace {

const char* yes_no(bool b) { return b ? "yes" : "no"; }
const char* on_off(bool b) { return b ? "on" : "off"; }

std::string volts(double v) { return fmt::format("{:.3f} V", v); }

// The order of the keys (rack, port, mac), for sorted output.
using RowKey = std::tuple<std::string_view, std::string_view, unsigned>;

}  // namespace

std::string ports_table(std::span<const PortRow> ports) {
  Table t({"RACK", "PORT", "BRIDGE", "STATE", "BUS", "LOAD", "FRAMES/S", "NODES", "INTERFACE",
           "REASON"});
  for (const auto& r : ports) {
    const auto& p = *r.port;
    t.add({std::string(view(p.rack)), std::string(view(p.port)), r.alive ? "live" : "gone",
           std::string(to_text(p.state)), std::string(to_text(p.bus_state)),
           fmt::format("{:.1f}%", p.bus_load_percent), fmt::format("{:.0f}", p.frames_per_second),
           fmt::format("{}/{} online", p.nodes_online, p.nodes_configured),
           fmt::format("{} {}k master {}", view(p.can_interface), p.bitrate / 1000, p.master_mac),
           std::string(view(p.reason))});
  }
  return t.render();
}

std::string nodes_table(std::span<const NodeRow> nodes) {
  Table t({"RACK", "PORT", "MAC", "NAME", "STATE", "ONLINE", "PRODUCT", "REASON"});
  for (const auto& r : nodes) {
    const auto& n = *r.node;
    t.add({std::string(view(n.rack)), std::string(view(n.port)), fmt::format("{}", n.mac),
           std::string(view(n.name)), std::string(to_text(n.state)), yes_no(node_online(r)),
           std::string(view(n.product_name)),
           r.alive ? std::string(view(n.reason)) : "bridge gone: " + std::string(view(n.reason))});
  }
  return t.render();
}

bool node_online(const NodeRow& r) {
  return r.alive && (r.pump ? r.pump->online : r.node->state == dnbridge_NODE_ONLINE);
}

void port_json_members(JsonWriter& out, const dnbridge_PortStatus& p) {
  out.field("port", view(p.port))
      .field("state", to_text(p.state))
      .field("reason", view(p.reason))
      .field("can_interface", view(p.can_interface))
      .field("bitrate", p.bitrate)
      .field("master_mac", unsigned{p.master_mac})
      .field("bus_state", to_text(p.bus_state))
      .field("tx_error_counter", unsigned{p.tx_error_counter})
      .field("rx_error_counter", unsigned{p.rx_error_counter});
  out.key("frames_per_second").number(p.frames_per_second, 1);
  out.key("bus_load_percent").number(p.bus_load_percent, 1);
  out.key("scan_cycle_ms").number(p.scan_cycle_ms, 1);
  out.field("nodes_online", unsigned{p.nodes_online})
      .field("nodes_configured", unsigned{p.nodes_configured})
      .field("explicit_outstanding", unsigned{p.explicit_outstanding})
      .field("explicit_retained", unsigned{p.explicit_retained})
      .field("explicit_refused_for_limits", std::uint64_t{p.explicit_refused_for_limits})
      .field("replies_undelivered", std::uint64_t{p.replies_undelivered});
  out.key("loop_longest_pass_ms").number(p.loop_longest_pass_ms, 2);
}

namespace {

void node_list_members(JsonWriter& out, const NodeRow& r) {
  const auto& n = *r.node;
  out.field("mac", unsigned{n.mac})
      .field("name", view(n.name))
      .field("state", to_text(n.state))
      .field("reason", view(n.reason))
      .field("product", view(n.product_name))
      .field("online", node_online(r));
}

}  // namespace

void list_json(JsonWriter& out, std::span<const PortRow> ports, std::span<const NodeRow> nodes) {
  // rack -> port -> (status, nodes), sorted by name.
  struct PortEntry {
    const PortRow* row = nullptr;
    std::vector<const NodeRow*> nodes;
  };
  std::map<std::string_view, std::map<std::string_view, PortEntry>> racks;
  for (const auto& r : ports) racks[view(r.port->rack)][view(r.port->port)].row = &r;
  for (const auto& r : nodes) racks[view(r.node->rack)][view(r.node->port)].nodes.push_back(&r);

  out.begin_object().key("racks").begin_array();
  for (auto& [rack, rack_ports] : racks) {
    bool alive = false;
    for (auto& [name, e] : rack_ports) {
      if (e.row && e.row->alive) alive = true;
      for (const auto* n : e.nodes) alive = alive || n->alive;
    }
    out.begin_object().field("rack", rack).field("bridge_alive", alive).key("ports").begin_array();
    for (auto& [name, e] : rack_ports) {
      out.begin_object();
      if (e.row) {
        port_json_members(out, *e.row->port);
      } else {
        out.field("port", name);
      }
      std::sort(e.nodes.begin(), e.nodes.end(),
                [](const NodeRow* a, const NodeRow* b) { return a->node->mac < b->node->mac; });
      out.key("nodes").begin_array();
      for (const auto* n : e.nodes) {
        out.begin_object();
        node_list_members(out, *n);
        out.end_object();
      }
      out.end_array().end_object();
    }
    out.end_array().end_object();
  }
  out.end_array().end_object();
}

std::string outputs_text(bool pump_on, bool n2_ballast_on, std::uint16_t analog_raw) {
  return fmt::format("pump {}, N2 ballast {}, analog out {} ({})", on_off(pump_on),
                     on_off(n2_ballast_on), analog_raw,
                     volts(static_cast<double>(analog_raw) * 10.0 / 4095.0));
}

std::string pump_line(const dnbridge_PumpState& s, std::string_view time_text) {
  std::string l = fmt::format("{} {} {}", time_text, node_name(view(s.rack), view(s.port), s.mac),
                              view(s.name));
  if (!s.online) return l + " offline";
  l += " online";
  if (s.inputs_valid) {
    l += fmt::format(" | {} warning={} alarm={} n2_flow={} interlock={}",
                     s.pump_running ? "running" : "stopped", yes_no(s.warning_active),
                     yes_no(s.alarm_active), s.n2_flow_ok ? "ok" : "low",
                     s.interlock_ok ? "ok" : "open");
  } else {
    l += " | no inputs yet";
  }
  for (unsigned i = 0; i < s.analog_input_count && i < 2; ++i) {
    l += s.analog_input_valid[i] ? fmt::format(" ai{}={:.3f}V", i + 1, s.analog_input_volts[i])
                                 : fmt::format(" ai{}=invalid({})", i + 1, s.analog_input_raw[i]);
  }
  if (s.outputs_idle) {
    l += view(s.idle_reason).empty() ? std::string(" | outputs idle")
                                     : fmt::format(" | outputs {}", view(s.idle_reason));
  } else {
    l += fmt::format(" | pump={} ballast={} aout={} ({:.3f}V) by \"{}\"", on_off(s.pump_on),
                     on_off(s.n2_ballast_on), s.analog_output_raw, s.analog_output_volts,
                     view(s.commanded_by));
  }
  return l;
}

std::string pumps_table(std::span<const dnbridge_PumpState* const> pumps) {
  Table t({"NODE", "NAME", "ONLINE", "RUNNING", "WARN", "ALARM", "N2", "INTERLOCK", "AI1", "AI2",
           "PUMP", "BALLAST", "AOUT", "COMMANDED BY"});
  for (const auto* p : pumps) {
    const auto& s = *p;
    const bool in = s.online && s.inputs_valid;
    const auto ai = [&](unsigned i) {
      if (!in || i >= s.analog_input_count) return std::string("-");
      return s.analog_input_valid[i] ? fmt::format("{:.3f}V", s.analog_input_volts[i])
                                     : fmt::format("invalid({})", s.analog_input_raw[i]);
    };
    const bool out = s.online && !s.outputs_idle;
    t.add({node_name(view(s.rack), view(s.port), s.mac), std::string(view(s.name)),
           yes_no(s.online), in ? yes_no(s.pump_running) : "-", in ? yes_no(s.warning_active) : "-",
           in ? yes_no(s.alarm_active) : "-", in ? (s.n2_flow_ok ? "ok" : "low") : "-",
           in ? (s.interlock_ok ? "ok" : "open") : "-", ai(0), ai(1),
           out ? on_off(s.pump_on) : "idle", out ? on_off(s.n2_ballast_on) : "idle",
           out ? fmt::format("{} ({:.3f}V)", s.analog_output_raw, s.analog_output_volts) : "idle",
           out ? std::string(view(s.commanded_by)) : ""});
  }
  return t.render();
}

void pump_json(JsonWriter& out, const dnbridge_PumpState& s) {
  out.begin_object()
      .field("rack", view(s.rack))
      .field("port", view(s.port))
      .field("mac", unsigned{s.mac})
      .field("name", view(s.name))
      .field("online", static_cast<bool>(s.online))
      .field("inputs_valid", static_cast<bool>(s.inputs_valid))
      .field("pump_running", static_cast<bool>(s.pump_running))
      .field("warning_active", static_cast<bool>(s.warning_active))
      .field("alarm_active", static_cast<bool>(s.alarm_active))
      .field("n2_flow_ok", static_cast<bool>(s.n2_flow_ok))
      .field("interlock_ok", static_cast<bool>(s.interlock_ok))
      .field("digital_inputs_raw", unsigned{s.digital_inputs_raw});
  out.key("analog_inputs").begin_array();
  for (unsigned i = 0; i < s.analog_input_count && i < 2; ++i) {
    out.begin_object().field("raw", unsigned{s.analog_input_raw[i]});
    out.field("valid", static_cast<bool>(s.analog_input_valid[i]));
    if (s.analog_input_valid[i]) {
      out.key("volts").number(s.analog_input_volts[i], 3);
    } else {
      out.key("volts").null();
    }
    out.end_object();
  }
  out.end_array();
  out.field("exception_status_valid", static_cast<bool>(s.exception_status_valid))
      .field("outputs_idle", static_cast<bool>(s.outputs_idle))
      .field("idle_reason", view(s.idle_reason))
      .field("pump_on", static_cast<bool>(s.pump_on))
      .field("n2_ballast_on", static_cast<bool>(s.n2_ballast_on))
      .field("analog_output_raw", unsigned{s.analog_output_raw});
  out.key("analog_output_volts").number(s.analog_output_volts, 3);
  out.field("commanded_by", view(s.commanded_by)).end_object();
}

std::string node_details(const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump, bool alive) {
  std::string o;
  const auto add = [&o](std::string_view label, const std::string& value) {
    o += fmt::format("{:<26}{}\n", label, value);
  };
  add("node", fmt::format("{} ({})", node_name(view(n.rack), view(n.port), n.mac), view(n.name)));
  add("state", fmt::format("{}{}", to_text(n.state), alive ? "" : " (bridge gone)"));
  add("reason", std::string(view(n.reason)));
  if (pump) add("online", yes_no(alive && pump->online));
  add("product name", std::string(view(n.product_name)));
  add("vendor", fmt::format("{} (0x{:04X})", n.vendor_id, n.vendor_id));
  add("product type", fmt::format("{} (0x{:04X})", n.product_type, n.product_type));
  add("product code", fmt::format("{} (0x{:04X})", n.product_code, n.product_code));
  add("revision", fmt::format("{}.{}", n.major_revision, n.minor_revision));
  add("serial number", fmt::format("{} (0x{:08X})", n.serial_number, n.serial_number));
  add("device state", n.device_state_valid
                          ? fmt::format("{} ({})", n.device_state, view(n.device_state_text))
                      : view(n.device_state_text).empty() ? std::string("not read")
                                                          : std::string(view(n.device_state_text)));
  add("poll", fmt::format("every {} ms, {} byte(s) out, {} byte(s) in", n.poll_period_ms,
                          n.consumed_size, n.produced_size));
  add("expected packet rate", fmt::format("{} ms", n.expected_packet_rate_ms));
  add("last error", view(n.last_error).empty()
                        ? std::string("none")
                        : fmt::format("{} (general status 0x{:02X}, additional 0x{:02X})",
                                      view(n.last_error), n.last_error_general_status,
                                      n.last_error_additional_status));
  add("last refused command",
      view(n.last_command_refused).empty() ? std::string("none") : std::string(view(n.last_command_refused)));
  add("invalid inputs",
      view(n.invalid_inputs).empty() ? std::string("none") : std::string(view(n.invalid_inputs)));
  if (pump && !pump->outputs_idle) {
    add("outputs", outputs_text(pump->pump_on, pump->n2_ballast_on, pump->analog_output_raw));
    add("commanded by", std::string(view(pump->commanded_by)));
  } else if (pump) {
    add("outputs", view(pump->idle_reason).empty() ? std::string("idle")
                                                   : std::string(view(pump->idle_reason)));
  }
  add("safe state", fmt::format("{} ({})", view(n.safe_state.text),
                                n.safe_state.source == dnbridge_SAFE_STATE_DEVICE
                                    ? "the device's own, kept"
                                    : "from the configuration, read back"));
  add("device faults",
      view(n.device_faults).empty() ? std::string("none") : std::string(view(n.device_faults)));
  const auto& c = n.counters;
  o += "counters\n";
  const auto counter = [&o](std::string_view label, std::uint64_t v) {
    o += fmt::format("  {:<24}{}\n", label, v);
  };
  counter("polls", c.polls);
  counter("idle polls", c.idle_polls);
  counter("poll responses", c.poll_responses);
  counter("poll timeouts", c.poll_timeouts);
  counter("poll retries", c.poll_retries);
  counter("poll errors", c.poll_errors);
  counter("reconnects", c.reconnects);
  counter("allocate attempts", c.allocate_attempts);
  counter("idle empty responses", c.idle_empty_responses);
  counter("settings written", c.settings_written);
  counter("explicit requests", c.explicit_requests);
  counter("explicit retries", c.explicit_retries);
  counter("explicit timeouts", c.explicit_timeouts);
  counter("explicit device errors", c.explicit_device_errors);
  counter("last fragment unacked", c.explicit_responses_before_final_ack);
  counter("invalid inputs", c.responses_with_invalid_inputs);
  counter("commands accepted", c.commands_accepted);
  counter("commands refused", c.commands_refused);
  return o;
}

namespace {

std::string_view safe_action_text(dnbridge_SafeAction a) {
  switch (a) {
    case dnbridge_SAFE_ACTION_UNKNOWN:
      return "unknown";
    case dnbridge_SAFE_ACTION_OFF:
      return "off";
    case dnbridge_SAFE_ACTION_ON:
      return "on";
    case dnbridge_SAFE_ACTION_HOLD:
      return "hold";
    case dnbridge_SAFE_ACTION_VALUE:
      return "value";
  }
  return "unknown";
}

void safe_state_json(JsonWriter& out, const dnbridge_SafeState& s) {
  out.key("safe_state")
      .begin_object()
      .field("known", static_cast<bool>(s.known))
      .field("source", s.source == dnbridge_SAFE_STATE_DEVICE ? "device" : "configured")
      .field("pump_on_fault", safe_action_text(s.pump_on_fault))
      .field("pump_on_idle", safe_action_text(s.pump_on_idle))
      .field("n2_ballast_on_fault", safe_action_text(s.n2_ballast_on_fault))
      .field("n2_ballast_on_idle", safe_action_text(s.n2_ballast_on_idle))
      .field("analog_output_on_fault", safe_action_text(s.analog_output_on_fault))
      .field("analog_output_fault_raw", unsigned{s.analog_output_fault_raw})
      .field("analog_output_on_idle", safe_action_text(s.analog_output_on_idle))
      .field("analog_output_idle_raw", unsigned{s.analog_output_idle_raw})
      .field("text", view(s.text))
      .end_object();
}

}  // namespace

void node_json(JsonWriter& out, const dnbridge_NodeStatus& n, const dnbridge_PumpState* pump,
               bool alive) {
  out.begin_object()
      .field("rack", view(n.rack))
      .field("port", view(n.port))
      .field("mac", unsigned{n.mac})
      .field("name", view(n.name))
      .field("bridge_alive", alive)
      .field("state", to_text(n.state))
      .field("reason", view(n.reason));
  if (pump) out.field("online", alive && pump->online);
  out.key("identity")
      .begin_object()
      .field("vendor_id", unsigned{n.vendor_id})
      .field("product_type", unsigned{n.product_type})
      .field("product_code", unsigned{n.product_code})
      .field("major_revision", unsigned{n.major_revision})
      .field("minor_revision", unsigned{n.minor_revision})
      .field("serial_number", unsigned{n.serial_number})
      .field("product_name", view(n.product_name))
      .end_object();
  out.key("device_state");
  if (n.device_state_valid) {
    out.begin_object()
        .field("code", unsigned{n.device_state})
        .field("text", view(n.device_state_text))
        .end_object();
  } else {
    out.null();
  }
  out.field("poll_period_ms", unsigned{n.poll_period_ms})
      .field("expected_packet_rate_ms", unsigned{n.expected_packet_rate_ms})
      .field("produced_size", unsigned{n.produced_size})
      .field("consumed_size", unsigned{n.consumed_size})
      .field("last_error", view(n.last_error))
      .field("last_error_general_status", unsigned{n.last_error_general_status})
      .field("last_error_additional_status", unsigned{n.last_error_additional_status})
      .field("last_command_refused", view(n.last_command_refused))
      .field("invalid_inputs", view(n.invalid_inputs))
      .field("device_faults", view(n.device_faults))
      .field("idle_reason", view(n.idle_reason));
  safe_state_json(out, n.safe_state);
  const auto& c = n.counters;
  out.key("counters")
      .begin_object()
      .field("polls", std::uint64_t{c.polls})
      .field("idle_polls", std::uint64_t{c.idle_polls})
      .field("poll_responses", std::uint64_t{c.poll_responses})
      .field("poll_timeouts", std::uint64_t{c.poll_timeouts})
      .field("poll_retries", std::uint64_t{c.poll_retries})
      .field("poll_errors", std::uint64_t{c.poll_errors})
      .field("reconnects", std::uint64_t{c.reconnects})
      .field("allocate_attempts", std::uint64_t{c.allocate_attempts})
      .field("idle_empty_responses", std::uint64_t{c.idle_empty_responses})
      .field("settings_written", std::uint64_t{c.settings_written})
      .field("explicit_requests", std::uint64_t{c.explicit_requests})
      .field("explicit_retries", std::uint64_t{c.explicit_retries})
      .field("explicit_timeouts", std::uint64_t{c.explicit_timeouts})
      .field("explicit_device_errors", std::uint64_t{c.explicit_device_errors})
      .field("explicit_responses_before_final_ack",
             std::uint64_t{c.explicit_responses_before_final_ack})
      .field("responses_with_invalid_inputs", std::uint64_t{c.responses_with_invalid_inputs})
      .field("commands_accepted", std::uint64_t{c.commands_accepted})
      .field("commands_refused", std::uint64_t{c.commands_refused})
      .end_object();
  if (pump) {
    out.key("pump");
    pump_json(out, *pump);
  }
  out.end_object();
}

namespace {

std::string request_text(const ExplicitExchange& x) {
  std::string s = fmt::format("{} {} class 0x{:02X} instance {}", node_name(x.rack, x.port, x.mac),
                              service_text(x.service), x.class_id, x.instance_id);
  if (x.attribute) s += fmt::format(" attribute {}", *x.attribute);
  if (!x.request_data.empty()) s += fmt::format(" data [{}]", hex_bytes(x.request_data));
  return s;
}

std::string_view decoding_name(Decoding as) {
  switch (as) {
    case Decoding::kString: return "string";
    case Decoding::kUint: return "uint";
    case Decoding::kInt: return "int";
    case Decoding::kNone: break;
  }
  return "";
}

}  // namespace

std::string explicit_text(const ExplicitExchange& x, Decoding as,
                          const std::optional<Parsed<std::string>>& decoded) {
  std::string o = request_text(x) + "\n";
  o += fmt::format("status: {} ({})\n", x.status, transaction_status_text(x.status));
  if (x.status == 1) {
    o += fmt::format("CIP general status: 0x{:02X} ({})", x.general_status,
                     general_status_text(x.general_status));
    if (x.additional_status != cip::kNoAdditionalCode) {
      o += fmt::format(", additional status 0x{:02X}", x.additional_status);
    }
    o += '\n';
  }
  if (!x.message.empty()) o += fmt::format("message: {}\n", x.message);
  if (!x.data.empty()) {
    o += fmt::format("data ({} byte{}): {}\n", x.data.size(), x.data.size() == 1 ? "" : "s",
                     hex_bytes(x.data));
  } else if (x.succeeded()) {
    o += "data: none\n";
  }
  if (decoded) {
    if (decoded->ok()) {
      o += fmt::format("as {}: {}\n", decoding_name(as),
                       as == Decoding::kString ? json_quote(**decoded) : **decoded);
    } else {
      o += fmt::format("as {}: cannot decode: {}\n", decoding_name(as), decoded->error());
    }
  }
  return o;
}

void explicit_json(JsonWriter& out, const ExplicitExchange& x, Decoding as,
                   const std::optional<Parsed<std::string>>& decoded) {
  out.begin_object().key("request").begin_object()
      .field("rack", x.rack)
      .field("port", x.port)
      .field("mac", unsigned{x.mac})
      .field("service", unsigned{x.service})
      .field("service_name", service_text(x.service))
      .field("class", unsigned{x.class_id})
      .field("instance", unsigned{x.instance_id});
  out.key("attribute");
  if (x.attribute) {
    out.value(unsigned{*x.attribute});
  } else {
    out.null();
  }
  out.field("data", hex_bytes(x.request_data)).end_object();
  out.field("status", unsigned{x.status})
      .field("status_text", transaction_status_text(x.status));
  // The device's status exists only when the bridge completed the transaction.
  if (x.status == 1) {
    out.field("general_status", unsigned{x.general_status})
        .field("general_status_text", general_status_text(x.general_status))
        .field("additional_status", unsigned{x.additional_status});
  } else {
    out.key("general_status").null().key("general_status_text").null().key("additional_status").null();
  }
  out.field("message", x.message)
      .field("data", hex_bytes(x.data))
      .field("succeeded", x.succeeded());
  if (decoded) {
    out.key("decoded").begin_object().field("as", decoding_name(as));
    if (decoded->ok() && as == Decoding::kString) {
      out.field("value", **decoded);
    } else if (decoded->ok()) {
      out.key("value").number_text(**decoded);  // an integer decode_data wrote
    } else {
      out.field("error", decoded->error());
    }
    out.end_object();
  }
  out.end_object();
}

}  // namespace dnbridge::dnbctl
