#include "adapters/dnbctl/format.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <tuple>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/states.hpp"
#include "adapters/dnbctl/utf8.hpp"
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
  if (cip::is_known(code))
    return std::string(cip::to_string(static_cast<cip::GeneralStatus>(code)));
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
  for (std::size_t c = 0; c < headers_.size(); ++c) width[c] = display_width(headers_[c]);
  for (const auto& row : rows_) {
    for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) {
      width[c] = std::max(width[c], display_width(row[c]));
    }
  }
  std::string out;
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string l;
    for (std::size_t c = 0; c < cells.size() && c < width.size(); ++c) {
      if (c != 0) l += "  ";
      l += cells[c];
      if (c + 1 < cells.size()) l.append(width[c] - display_width(cells[c]), ' ');
    }
    while (!l.empty() && l.back() == ' ') l.pop_back();
    out += l;
    out += '\n';
  };
  line(headers_);
  for (const auto& row : rows_) line(row);
  return out;
}

std::string table(std::span<const std::string_view> labels, std::span<const Record> rows) {
  std::vector<std::string> headers;
  for (auto label : labels) {
    std::string h(label);
    std::transform(h.begin(), h.end(), h.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    headers.push_back(std::move(h));
  }
  Table t(std::move(headers));
  for (const auto& r : rows) {
    std::vector<std::string> cells;
    for (auto label : labels) cells.push_back(r.text_of(label));
    t.add(std::move(cells));
  }
  return t.render();
}

namespace {

const char* yes_no(bool b) { return b ? "yes" : "no"; }
const char* on_off(bool b) { return b ? "on" : "off"; }

std::string volts(double v) { return fmt::format("{:.3f} V", v); }

// The order of the keys (rack, port, mac), for sorted output.
using RowKey = std::tuple<std::string_view, std::string_view, unsigned>;

// "8/8 online", and the MACs heard that the configuration does not have:
// "7/8 online; unconfigured heard: 17, 23".
std::string nodes_text(const dnbridge_PortStatus& p) {
  std::string s = fmt::format("{}/{} online", p.nodes_online, p.nodes_configured);
  const auto macs = view(p.unconfigured_macs);
  if (!macs.empty()) s += fmt::format("; unconfigured heard: {}", fmt::join(macs, ", "));
  return s;
}

// "lease at most 10000 ms", with the commanders and endpoints the bridge
// does not match: "lease at most 10000 ms; 1 commander refused, 2 endpoints
// unmatched (the bridge's log says who)".
std::string commanders_text(const dnbridge_PortStatus& p) {
  std::string s = fmt::format("lease at most {} ms", p.max_commander_lease_ms);
  if (p.commanders_refused == 0 && p.endpoints_unmatched == 0) return s;
  s += fmt::format("; {} commander{} refused, {} endpoint{} unmatched (the bridge's log says who)",
                   p.commanders_refused, p.commanders_refused == 1 ? "" : "s",
                   p.endpoints_unmatched, p.endpoints_unmatched == 1 ? "" : "s");
  return s;
}

Json unconfigured_json(const dnbridge_PortStatus& p) {
  std::vector<Json> macs;
  for (const auto mac : view(p.unconfigured_macs)) macs.emplace_back(static_cast<unsigned>(mac));
  return Json::values(std::move(macs));
}

}  // namespace

Record port_record(const dnbridge_PortStatus& p) {
  Record r;
  r.add("port", std::string(view(p.port)), "port", view(p.port))
      .add("state", std::string(to_text(p.state)), "state", to_text(p.state))
      .add("reason", std::string(view(p.reason)), "reason", view(p.reason))
      .add("interface",
           fmt::format("{} {}k master {}", view(p.can_interface), p.bitrate / 1000, p.master_mac),
           {{"can_interface", view(p.can_interface)},
            {"bitrate", p.bitrate},
            {"master_mac", p.master_mac}})
      .add("bus", std::string(to_text(p.bus_state)), "bus_state", to_text(p.bus_state))
      .json("tx_error_counter", p.tx_error_counter)
      .json("rx_error_counter", p.rx_error_counter)
      .add("frames/s", fmt::format("{:.0f}", p.frames_per_second), "frames_per_second",
           Decimal{p.frames_per_second, 1})
      .add("load", fmt::format("{:.1f}%", p.bus_load_percent), "bus_load_percent",
           Decimal{p.bus_load_percent, 1})
      .json("scan_cycle_ms", Decimal{p.scan_cycle_ms, 1})
      .add("nodes", nodes_text(p),
           {{"nodes_online", p.nodes_online},
            {"nodes_configured", p.nodes_configured},
            {"unconfigured_macs", unconfigured_json(p)}})
      .json("explicit_outstanding", p.explicit_outstanding)
      .json("explicit_retained", p.explicit_retained)
      .json("explicit_refused_for_limits", p.explicit_refused_for_limits)
      .json("replies_undelivered", p.replies_undelivered)
      .json("loop_longest_pass_ms", Decimal{p.loop_longest_pass_ms, 2})
      .add("commanders", commanders_text(p),
           {{"max_commander_lease_ms", p.max_commander_lease_ms},
            {"commanders_refused", p.commanders_refused},
            {"endpoints_unmatched", p.endpoints_unmatched}});
  return r;
}

void port_json_members(JsonWriter& out, const dnbridge_PortStatus& p) {
  port_record(p).write_members(out);
}

std::string ports_table(std::span<const PortRow> ports) {
  static constexpr std::string_view kColumns[] = {
      "rack", "port", "bridge", "state", "bus", "load", "frames/s", "nodes", "interface", "reason"};
  std::vector<Record> rows;
  for (const auto& r : ports) {
    rows.push_back(port_record(*r.port)
                       .text("rack", std::string(view(r.port->rack)))
                       .text("bridge", r.alive ? "live" : "gone"));
  }
  return table(kColumns, rows);
}

std::optional<bool> NodeRow::online() const {
  if (pump) return pump->online;
  if (device) return device->online;
  return std::nullopt;
}

std::optional<bool> NodeRow::outputs_idle() const {
  if (pump) return pump->outputs_idle;
  if (device) return device->outputs_idle;
  return std::nullopt;
}

std::string_view NodeRow::idle_reason() const {
  return pump ? view(pump->idle_reason) : device ? view(device->idle_reason) : std::string_view{};
}

std::string_view NodeRow::commanded_by() const {
  return pump ? view(pump->commanded_by) : device ? view(device->commanded_by) : std::string_view{};
}

bool node_online(const NodeRow& r) {
  return r.alive && r.online().value_or(r.node->state == dnbridge_NODE_ONLINE);
}

namespace {

// A node as `list` shows it.
Record node_row_record(const NodeRow& r) {
  const auto& n = *r.node;
  Record rec;
  rec.text("rack", std::string(view(n.rack)))
      .text("port", std::string(view(n.port)))
      .add("mac", fmt::format("{}", n.mac), "mac", n.mac)
      .add("name", std::string(view(n.name)), "name", view(n.name))
      .add("state", std::string(to_text(n.state)), "state", to_text(n.state))
      .add("reason",
           r.alive ? std::string(view(n.reason)) : "bridge gone: " + std::string(view(n.reason)),
           "reason", view(n.reason))
      .add("product", std::string(view(n.product_name)), "product", view(n.product_name))
      .add("online", yes_no(node_online(r)), "online", node_online(r));
  return rec;
}

}  // namespace

std::string nodes_table(std::span<const NodeRow> nodes) {
  static constexpr std::string_view kColumns[] = {"rack",  "port",   "mac",     "name",
                                                  "state", "online", "product", "reason"};
  std::vector<Record> rows;
  for (const auto& r : nodes) rows.push_back(node_row_record(r));
  return table(kColumns, rows);
}

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
      for (const auto* n : e.nodes) node_row_record(*n).write(out);
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

namespace {

// A pump's PumpState as `watch` and `show` show it.
Record pump_record(const dnbridge_PumpState& s) {
  const bool in = s.online && s.inputs_valid;
  const bool out = s.online && !s.outputs_idle;
  const auto input = [in](bool v, const char* yes, const char* no) {
    return std::string(in ? (v ? yes : no) : "-");
  };
  const auto ai = [&](unsigned i) {
    if (!in || i >= s.analog_input_count) return std::string("-");
    return s.analog_input_valid[i] ? fmt::format("{:.3f}V", s.analog_input_volts[i])
                                   : fmt::format("invalid({})", s.analog_input_raw[i]);
  };
  std::vector<Record> analog_inputs;
  for (unsigned i = 0; i < s.analog_input_count && i < 2; ++i) {
    Record channel;
    channel.json("raw", s.analog_input_raw[i])
        .json("valid", static_cast<bool>(s.analog_input_valid[i]))
        .json("volts",
              s.analog_input_valid[i] ? Json(Decimal{s.analog_input_volts[i], 3}) : Json());
    analog_inputs.push_back(std::move(channel));
  }
  Record r;
  r.add("node", node_name(view(s.rack), view(s.port), s.mac),
        {{"rack", view(s.rack)}, {"port", view(s.port)}, {"mac", s.mac}})
      .add("name", std::string(view(s.name)), "name", view(s.name))
      .add("online", yes_no(s.online), "online", static_cast<bool>(s.online))
      .json("inputs_valid", static_cast<bool>(s.inputs_valid))
      .add("running", input(s.pump_running, "yes", "no"), "pump_running",
           static_cast<bool>(s.pump_running))
      .add("warn", input(s.warning_active, "yes", "no"), "warning_active",
           static_cast<bool>(s.warning_active))
      .add("alarm", input(s.alarm_active, "yes", "no"), "alarm_active",
           static_cast<bool>(s.alarm_active))
      .add("n2", input(s.n2_flow_ok, "ok", "low"), "n2_flow_ok", static_cast<bool>(s.n2_flow_ok))
      .add("interlock", input(s.interlock_ok, "ok", "open"), "interlock_ok",
           static_cast<bool>(s.interlock_ok))
      .json("digital_inputs_raw", s.digital_inputs_raw)
      .text("ai1", ai(0))
      .text("ai2", ai(1))
      .json("analog_inputs", Json::array(std::move(analog_inputs)))
      .json("exception_status_valid", static_cast<bool>(s.exception_status_valid))
      .json("outputs_idle", static_cast<bool>(s.outputs_idle))
      .json("idle_reason", view(s.idle_reason))
      .add("pump", out ? on_off(s.pump_on) : "idle", "pump_on", static_cast<bool>(s.pump_on))
      .add("ballast", out ? on_off(s.n2_ballast_on) : "idle", "n2_ballast_on",
           static_cast<bool>(s.n2_ballast_on))
      .add("aout",
           out ? fmt::format("{} ({:.3f}V)", s.analog_output_raw, s.analog_output_volts) : "idle",
           {{"analog_output_raw", s.analog_output_raw},
            {"analog_output_volts", Decimal{s.analog_output_volts, 3}}})
      .add("commanded by", out ? std::string(view(s.commanded_by)) : "", "commanded_by",
           view(s.commanded_by));
  return r;
}

}  // namespace

std::string pumps_table(std::span<const dnbridge_PumpState* const> pumps) {
  static constexpr std::string_view kColumns[] = {
      "node",      "name", "online", "running", "warn",    "alarm", "n2",
      "interlock", "ai1",  "ai2",    "pump",    "ballast", "aout",  "commanded by"};
  std::vector<Record> rows;
  for (const auto* p : pumps) rows.push_back(pump_record(*p));
  return table(kColumns, rows);
}

void pump_json(JsonWriter& out, const dnbridge_PumpState& s) { pump_record(s).write(out); }

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
    case Decoding::kString:
      return "string";
    case Decoding::kUint:
      return "uint";
    case Decoding::kInt:
      return "int";
    case Decoding::kNone:
      break;
  }
  return "";
}

}  // namespace

namespace {

// A request and its reply as `get`, `set` and `service` show them: in text
// one line per field, "label: value", the request's own line first.
Record explicit_record(const ExplicitExchange& x, Decoding as,
                       const std::optional<Parsed<std::string>>& decoded) {
  Record request;
  request.json("rack", x.rack)
      .json("port", x.port)
      .json("mac", x.mac)
      .json("service", x.service)
      .json("service_name", service_text(x.service))
      .json("class", x.class_id)
      .json("instance", x.instance_id)
      .json("attribute", x.attribute ? Json(*x.attribute) : Json())
      .json("data", hex_bytes(x.request_data));

  Record r;
  r.add(request_text(x), "", "request", Json::object(std::move(request)))
      .add("status: ", fmt::format("{} ({})", x.status, transaction_status_text(x.status)),
           {{"status", x.status}, {"status_text", transaction_status_text(x.status)}});
  // The device's status exists only when the bridge completed the transaction.
  if (x.status == 1) {
    std::string text =
        fmt::format("0x{:02X} ({})", x.general_status, general_status_text(x.general_status));
    if (x.additional_status != cip::kNoAdditionalCode) {
      text += fmt::format(", additional status 0x{:02X}", x.additional_status);
    }
    r.add("CIP general status: ", std::move(text),
          {{"general_status", x.general_status},
           {"general_status_text", general_status_text(x.general_status)},
           {"additional_status", x.additional_status}});
  } else {
    r.add("", "", {{"general_status", {}}, {"general_status_text", {}}, {"additional_status", {}}});
  }
  r.add(x.message.empty() ? "" : "message: ", x.message, "message", x.message);
  std::string data_label;
  if (!x.data.empty()) {
    data_label = fmt::format("data ({} byte{}): ", x.data.size(), x.data.size() == 1 ? "" : "s");
  } else if (x.succeeded()) {
    data_label = "data: ";
  }
  r.add(std::move(data_label), x.data.empty() ? "none" : hex_bytes(x.data), "data",
        hex_bytes(x.data))
      .json("succeeded", x.succeeded());
  if (decoded) {
    Record d;
    d.json("as", decoding_name(as));
    std::string text;
    if (decoded->ok() && as == Decoding::kString) {
      d.json("value", **decoded);
      text = json_quote(**decoded);
    } else if (decoded->ok()) {
      d.json("value", Json::digits(**decoded));  // an integer decode_data wrote
      text = **decoded;
    } else {
      d.json("error", decoded->error());
      text = "cannot decode: " + decoded->error();
    }
    r.add(fmt::format("as {}: ", decoding_name(as)), std::move(text), "decoded",
          Json::object(std::move(d)));
  }
  return r;
}

}  // namespace

std::string explicit_text(const ExplicitExchange& x, Decoding as,
                          const std::optional<Parsed<std::string>>& decoded) {
  return explicit_record(x, as, decoded).lines(0);
}

void explicit_json(JsonWriter& out, const ExplicitExchange& x, Decoding as,
                   const std::optional<Parsed<std::string>>& decoded) {
  explicit_record(x, as, decoded).write(out);
}

std::string_view reload_status_word(std::uint8_t status) {
  switch (status) {
    case dnbridge_RELOAD_APPLIED:
      return "applied";
    case dnbridge_RELOAD_REFUSED:
      return "refused";
    case dnbridge_RELOAD_BUSY:
      return "busy";
    case dnbridge_RELOAD_NO_FILE:
      return "no-file";
    case dnbridge_RELOAD_INCOMPLETE:
      return "incomplete";
    default:
      break;
  }
  return "unknown";
}

namespace {

// A list of the reply as `reload` shows it: in text its heading, then one
// indented line per entry, nothing when empty; in JSON an array of strings.
void add_lines(Record& r, std::string heading, std::string key, const dds_sequence_string& seq) {
  std::vector<std::string_view> entries;
  if (seq._buffer != nullptr) {
    for (std::uint32_t i = 0; i < seq._length; ++i) entries.push_back(view(seq._buffer[i]));
  }
  std::vector<Json> items(entries.begin(), entries.end());
  r.add(entries.empty() ? "" : std::move(heading), "", std::move(key),
        Json::values(std::move(items)));
  for (const auto e : entries) r.text(fmt::format("  {}", e), "");
}

// A reload's reply as `reload` shows it.
Record reload_record(const dnbridge_ReloadReply& r) {
  const std::string_view word = reload_status_word(r.status);
  const std::string message(view(r.message));
  const std::string file(view(r.file));
  Record rec;
  rec.add(fmt::format("rack {}: {}", view(r.rack), message.empty() ? word : message), "",
          {{"rack", std::string(view(r.rack))}, {"status", word}, {"message", message}})
      .add(file.empty() ? "" : "file: ", file, "file", file);
  add_lines(rec, "applied:", "applied", r.applied);
  add_lines(rec, "needs a restart:", "needs_restart", r.needs_restart);
  add_lines(rec, "problems:", "problems", r.problems);
  return rec;
}

}  // namespace

std::string reload_text(const dnbridge_ReloadReply& r) { return reload_record(r).lines(0); }

void reload_json(JsonWriter& out, const dnbridge_ReloadReply& r) { reload_record(r).write(out); }

std::string failure_text(const ExplicitExchange& x) {
  if (x.status != 1) {
    return fmt::format("status {} ({}){}", x.status, transaction_status_text(x.status),
                       x.message.empty() ? "" : ": " + x.message);
  }
  return fmt::format("the device answered 0x{:02X} ({})", x.general_status,
                     general_status_text(x.general_status));
}

}  // namespace dnbridge::dnbctl
