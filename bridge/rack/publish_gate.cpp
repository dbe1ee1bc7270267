#include "bridge/rack/publish_gate.hpp"

#include <cmath>

namespace dnbridge::rack {

PumpStateGate::Discrete PumpStateGate::discrete(const PumpView& v) {
  Discrete d;
  d.online = v.online;
  d.inputs_valid = v.has_inputs;
  if (v.has_inputs) {
    d.input_bits = v.inputs.input_bits.value_or(0);
    d.has_exception = v.inputs.exception_status.has_value();
    if (d.has_exception) d.exception_bits = v.inputs.exception_status->encode();
    d.analog_in_range = v.inputs.analog_input_in_range;
  }
  d.outputs_idle = v.outputs_idle;
  if (!v.outputs_idle) d.outputs = v.outputs_applied;
  return d;
}

std::array<int, 2> PumpStateGate::analog(const PumpView& v) {
  std::array<int, 2> a{-1, -1};
  if (!v.has_inputs) return a;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (v.inputs.analog_inputs_raw[i]) a[i] = *v.inputs.analog_inputs_raw[i];
  }
  return a;
}

bool PumpStateGate::changed(const NodeView& node) const {
  const auto& view = static_cast<const PumpView&>(node);
  if (!(discrete(view) == last_)) return true;
  if (view.commanded_by != last_commander_) return true;
  const auto now_analog = analog(view);
  for (std::size_t i = 0; i < now_analog.size(); ++i) {
    const int before = last_analog_[i];
    const int after = now_analog[i];
    if ((before < 0) != (after < 0)) return true;  // appeared or disappeared
    if (before < 0) continue;
    const double delta =
        std::abs(profiles::cdn127::raw_to_volts(static_cast<std::uint16_t>(after)) -
                 profiles::cdn127::raw_to_volts(static_cast<std::uint16_t>(before)));
    if (delta > policy().analog_deadband_volts) return true;
  }
  return false;
}

void PumpStateGate::record(const NodeView& node) {
  const auto& view = static_cast<const PumpView&>(node);
  last_ = discrete(view);
  last_analog_ = analog(view);
  last_commander_ = view.commanded_by;
}

DeviceStateGate::Seen DeviceStateGate::seen(const DeviceView& v) {
  Seen s;
  s.online = v.online;
  s.inputs_valid = v.has_inputs;
  if (v.has_inputs) s.inputs = v.inputs;
  s.outputs_idle = v.outputs_idle;
  if (!v.outputs_idle) s.outputs = v.outputs_applied;
  s.commanded_by = v.commanded_by;
  return s;
}

bool DeviceStateGate::changed(const NodeView& view) const {
  return !(seen(static_cast<const DeviceView&>(view)) == last_);
}

void DeviceStateGate::record(const NodeView& view) {
  last_ = seen(static_cast<const DeviceView&>(view));
}

}  // namespace dnbridge::rack
