#include "adapters/demo/scenario.hpp"

#include <fmt/format.h>

namespace dnbridge::demo {
namespace {

devicenet::MacId mac(unsigned v) { return devicenet::MacId::from(v).value(); }

profiles::cdn127::PumpOutputs outputs(bool on, bool ballast, std::uint16_t aout) {
  profiles::cdn127::PumpOutputs o;
  o.pump_on = on;
  o.n2_ballast_on = ballast;
  o.analog_out_raw = aout;
  return o;
}

}  // namespace

Duration scenario_period() { return seconds(60); }

std::vector<ScenarioStep> make_scenario(const std::vector<unsigned>& macs) {
  std::vector<ScenarioStep> steps;
  if (macs.empty()) return steps;
  // Start the pumps one after the other, as an operator would.
  for (std::size_t i = 0; i < macs.size(); ++i) {
    const unsigned m = macs[i];
    const auto aout = static_cast<std::uint16_t>(1000 + 300 * i);
    steps.push_back({seconds(6) + milliseconds(500) * static_cast<int>(i),
                     fmt::format("supervisor starts pump {} (analog out {})", m, aout),
                     [m, aout](sim::SimRack& r, TimePoint now) {
                       (void)r.pumps().command(mac(m), outputs(true, true, aout), now);
                     }});
  }
  // Analog inputs drift.
  for (std::size_t i = 0; i < macs.size(); ++i) {
    const unsigned m = macs[i];
    steps.push_back({seconds(10), fmt::format("pump {} inlet pressure and temperature read in", m),
                     [m, i](sim::SimRack& r, TimePoint) {
                       auto& pump = r.device(mac(m)).device().pump();
                       pump.set_analog_input(0, static_cast<std::uint16_t>(800 + 150 * i));
                       pump.set_analog_input(1, static_cast<std::uint16_t>(2400 - 100 * i));
                     }});
  }
  const unsigned a = macs[0];
  const unsigned b = macs.size() > 1 ? macs[1] : macs[0];
  const unsigned c = macs.size() > 2 ? macs[2] : macs[0];
  steps.push_back({seconds(18), fmt::format("pump {}: N2 ballast flow lost", a),
                   [a](sim::SimRack& r, TimePoint) {
                     r.device(mac(a)).device().pump().set_n2_flow_ok(false);
                   }});
  steps.push_back({seconds(22), fmt::format("pump {}: interlock opens (pump fail)", b),
                   [b](sim::SimRack& r, TimePoint now) {
                     r.device(mac(b)).device().pump().set_alarm(true, now);
                   }});
  steps.push_back(
      {seconds(26), fmt::format("pump {}: power cycled", c),
       [c](sim::SimRack& r, TimePoint now) { r.device(mac(c)).device().power_cycle(now); }});
  steps.push_back(
      {seconds(32), fmt::format("pump {}: N2 flow back", a),
       [a](sim::SimRack& r, TimePoint) { r.device(mac(a)).device().pump().set_n2_flow_ok(true); }});
  steps.push_back(
      {seconds(34), fmt::format("pump {}: alarm cleared", b), [b](sim::SimRack& r, TimePoint now) {
         r.device(mac(b)).device().pump().set_alarm(false, now);
       }});
  steps.push_back(
      {seconds(38), fmt::format("pump {}: its supervisor goes away (idle)", a),
       [a](sim::SimRack& r, TimePoint now) { (void)r.pumps().release_command(mac(a), now); }});
  // Everything off at the end of the cycle, then it starts over.
  for (unsigned m : macs) {
    steps.push_back({seconds(50), fmt::format("supervisor stops pump {}", m),
                     [m](sim::SimRack& r, TimePoint now) {
                       (void)r.pumps().command(mac(m), outputs(false, false, 0), now);
                     }});
  }
  return steps;
}

}  // namespace dnbridge::demo
