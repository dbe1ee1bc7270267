#include "adapters/demo/rack_table.hpp"

#include <fmt/format.h>

namespace dnbridge::demo {
namespace {

std::string flag(bool value, const char* yes, const char* no) { return value ? yes : no; }

std::string analog(const std::optional<std::uint16_t>& raw) {
  if (!raw) return "    -  ";
  return fmt::format("{:5.2f} V", profiles::cdn127::raw_to_volts(*raw));
}

}  // namespace

std::string render_rack(sim::SimRack& rack, TimePoint started,
                        const std::deque<std::string>& events) {
  const TimePoint now = rack.now();
  auto& bus = rack.world().bus();
  std::string out;
  out += fmt::format("dnbridge demo: master MAC {} on a simulated {} kbit/s bus, t = {:.1f} s\n",
                     rack.scanner().config().master_mac.value(), bus.bitrate() / 1000,
                     std::chrono::duration<double>(now - started).count());
  out += fmt::format("port: {} ({}); bus load {:.1f} %, {} frames\n\n",
                     devicenet::to_string(rack.scanner().state()), rack.scanner().reason(),
                     100.0 * bus.bus_load(now), bus.stats().transmitted);
  out += fmt::format(
      "{:>3}  {:<8} {:<20} {:<9} {:<8} {:<7} {:<6} {:<6} {:<7} {:>7}  {:>7}  {:>7}  {:>7} {:>6}\n",
      "MAC", "name", "state", "command", "running", "warning", "alarm", "N2", "ilock", "AIN1",
      "AIN2", "AOUT", "polls", "errors");
  for (const auto& v : rack.pumps().pumps()) {
    const auto* node = rack.scanner().node(v.mac);
    std::string command = "-";
    if (v.online) {
      command = v.outputs_idle ? "idle"
                               : fmt::format("{}{}", v.outputs_applied.pump_on ? "ON" : "off",
                                             v.outputs_applied.n2_ballast_on ? "+N2" : "");
    }
    const auto& pump = v.inputs.pump;
    const bool have = v.online && v.has_inputs && pump.has_value();
    out += fmt::format(
        "{:>3}  {:<8} {:<20} {:<9} {:<8} {:<7} {:<6} {:<6} {:<7} {:>7}  {:>7}  {:>7}  {:>7} "
        "{:>6}\n",
        v.mac.value(), v.name, devicenet::to_string(v.state), command,
        have ? flag(pump->pump_running, "RUNNING", "stopped") : "-",
        have ? flag(pump->warning_active, "WARN", "ok") : "-",
        have ? flag(pump->alarm_active, "ALARM", "ok") : "-",
        have ? flag(pump->n2_flow_ok, "ok", "NO FLOW") : "-",
        have ? flag(pump->interlock_ok, "ok", "OPEN") : "-",
        v.online ? analog(v.inputs.analog_inputs_raw[0]) : "-",
        v.online ? analog(v.inputs.analog_inputs_raw[1]) : "-",
        v.online && !v.outputs_idle
            ? fmt::format("{:5.2f} V",
                          profiles::cdn127::raw_to_volts(v.outputs_applied.analog_out_raw))
            : "-",
        node ? node->counters().polls : 0, node ? node->counters().errors : 0);
  }
  out += "\nlast events:\n";
  for (const auto& e : events) out += "  " + e + "\n";
  return out;
}

}  // namespace dnbridge::demo
