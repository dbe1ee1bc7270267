// watch: a pump's PumpState as a line per sample, as a table row and as
// JSON; the outputs as they read.
#include <fmt/format.h>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/format_internal.hpp"

namespace dnbridge::dnbctl {

using dds::view;
using format_detail::on_off;
using format_detail::pump_record;
using format_detail::yes_no;

namespace {

std::string volts(double v) { return fmt::format("{:.3f} V", v); }

}  // namespace

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

namespace format_detail {

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

}  // namespace format_detail

std::string pumps_table(std::span<const dnbridge_PumpState* const> pumps) {
  static constexpr std::string_view kColumns[] = {
      "node",      "name", "online", "running", "warn",    "alarm", "n2",
      "interlock", "ai1",  "ai2",    "pump",    "ballast", "aout",  "commanded by"};
  std::vector<Record> rows;
  for (const auto* p : pumps) rows.push_back(pump_record(*p));
  return table(kColumns, rows);
}

void pump_json(JsonWriter& out, const dnbridge_PumpState& s) { pump_record(s).write(out); }

}  // namespace dnbridge::dnbctl
