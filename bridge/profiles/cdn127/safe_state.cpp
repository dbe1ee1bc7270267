#include "bridge/profiles/cdn127/safe_state.hpp"

#include <fmt/format.h>

#include <array>

#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::profiles::cdn127 {
namespace {

// DOP attribute values (manual, DOP object): the action BOOL is 0 "use the
// value", 1 "no change"; the value BOOL 0 off, 1 on.
constexpr std::uint8_t kUseValue = 0, kNoChange = 1;
// AOP Fault/Idle State: 0 hold, 1 low limit (0 V), 2 high limit (10 V), 3 the value.
constexpr std::uint8_t kAopHold = 0, kAopLow = 1, kAopHigh = 2, kAopValue = 3;

constexpr std::array<const char*, 2> kDopNames = {"DOP 1 (pump)", "DOP 2 (N2 ballast)"};

devicenet::AttributeSetting setting(std::uint16_t class_id, std::uint8_t instance,
                                    std::uint8_t attribute, std::vector<std::uint8_t> value,
                                    std::string name, SafeStateSource source,
                                    std::uint32_t device_max) {
  devicenet::AttributeSetting s;
  s.class_id = class_id;
  s.instance_id = instance;
  s.attribute = attribute;
  s.value = std::move(value);
  s.name = std::move(name);
  s.keep_device_value = source == SafeStateSource::kDevice;
  s.device_value_max = device_max;
  return s;
}

// One discrete output's action and value attributes: the value first, so
// that the action never applies a value not yet written.
void add_discrete(std::vector<devicenet::AttributeSetting>& out, std::uint8_t instance,
                  DiscreteAction action, bool fault, SafeStateSource source) {
  const char* object = kDopNames[instance - 1u];
  const char* what = fault ? "Fault" : "Idle";
  const std::uint8_t action_attr = fault ? dop_attr::kFaultAction : dop_attr::kIdleAction;
  const std::uint8_t value_attr = fault ? dop_attr::kFaultValue : dop_attr::kIdleValue;
  if (action != DiscreteAction::kHold || source == SafeStateSource::kDevice) {
    out.push_back(setting(class_id::kDiscreteOutputPoint, instance, value_attr,
                          {action == DiscreteAction::kOn ? std::uint8_t{1} : std::uint8_t{0}},
                          fmt::format("{}.{}Value", object, what), source, 1));
  }
  out.push_back(setting(class_id::kDiscreteOutputPoint, instance, action_attr,
                        {action == DiscreteAction::kHold ? kNoChange : kUseValue},
                        fmt::format("{}.{}Action", object, what), source, 1));
}

void add_analog(std::vector<devicenet::AttributeSetting>& out, const AnalogAction& action,
                bool fault, SafeStateSource source) {
  const char* what = fault ? "Fault" : "Idle";
  const std::uint8_t state_attr = fault ? aop_attr::kFaultState : aop_attr::kIdleState;
  const std::uint8_t value_attr = fault ? aop_attr::kFaultValue : aop_attr::kIdleValue;
  std::uint8_t state = kAopValue;
  switch (action.kind) {
    case AnalogAction::Kind::kHold:
      state = kAopHold;
      break;
    case AnalogAction::Kind::kLowLimit:
      state = kAopLow;
      break;
    case AnalogAction::Kind::kHighLimit:
      state = kAopHigh;
      break;
    case AnalogAction::Kind::kValue:
      break;
  }
  if (state == kAopValue || source == SafeStateSource::kDevice) {
    const std::uint16_t raw = state == kAopValue ? action.raw : 0;
    out.push_back(
        setting(class_id::kAnalogOutputPoint, 1, value_attr,
                {static_cast<std::uint8_t>(raw & 0xFF), static_cast<std::uint8_t>(raw >> 8)},
                fmt::format("AOP 1.{}Value", what), source, kAnalogMaxRaw));
  }
  out.push_back(setting(class_id::kAnalogOutputPoint, 1, state_attr, {state},
                        fmt::format("AOP 1.{}State", what), source, kAopValue));
}

// Which safe-state slot a setting is, if any.
struct Slot {
  enum class Output : std::uint8_t { kPump, kBallast, kAnalog } output;
  bool fault;
  bool is_value;  // the value rather than the action / state
};

std::optional<Slot> slot_of(const devicenet::AttributeSetting& s) {
  if (s.class_id == class_id::kDiscreteOutputPoint && (s.instance_id == 1 || s.instance_id == 2)) {
    const auto output = s.instance_id == 1 ? Slot::Output::kPump : Slot::Output::kBallast;
    switch (s.attribute) {
      case dop_attr::kFaultAction:
        return Slot{output, true, false};
      case dop_attr::kFaultValue:
        return Slot{output, true, true};
      case dop_attr::kIdleAction:
        return Slot{output, false, false};
      case dop_attr::kIdleValue:
        return Slot{output, false, true};
      default:
        return std::nullopt;
    }
  }
  if (s.class_id == class_id::kAnalogOutputPoint && s.instance_id == 1) {
    switch (s.attribute) {
      case aop_attr::kFaultState:
        return Slot{Slot::Output::kAnalog, true, false};
      case aop_attr::kFaultValue:
        return Slot{Slot::Output::kAnalog, true, true};
      case aop_attr::kIdleState:
        return Slot{Slot::Output::kAnalog, false, false};
      case aop_attr::kIdleValue:
        return Slot{Slot::Output::kAnalog, false, true};
      default:
        return std::nullopt;
    }
  }
  return std::nullopt;
}

// What was read of one output's fault or idle attributes.
struct Read {
  std::optional<std::uint16_t> action;
  std::optional<std::uint16_t> value;
};

std::optional<DiscreteAction> discrete(const Read& r) {
  if (!r.action) return DiscreteAction::kOff;  // an output the configuration leaves out
  if (*r.action == kNoChange) return DiscreteAction::kHold;
  if (*r.action != kUseValue || !r.value || *r.value > 1) return std::nullopt;
  return *r.value == 1 ? DiscreteAction::kOn : DiscreteAction::kOff;
}

std::optional<AnalogAction> analog(const Read& r) {
  if (!r.action) return AnalogAction{};
  switch (*r.action) {
    case kAopHold:
      return AnalogAction{AnalogAction::Kind::kHold, 0};
    case kAopLow:
      return AnalogAction{AnalogAction::Kind::kLowLimit, 0};
    case kAopHigh:
      return AnalogAction{AnalogAction::Kind::kHighLimit, kAnalogMaxRaw};
    case kAopValue:
      if (!r.value || *r.value > kAnalogMaxRaw) return std::nullopt;
      return AnalogAction{AnalogAction::Kind::kValue, *r.value};
    default:
      return std::nullopt;
  }
}

std::optional<std::uint16_t> little_endian(const std::vector<std::uint8_t>& v) {
  if (v.size() == 1) return v[0];
  if (v.size() == 2) return static_cast<std::uint16_t>(v[0] | (v[1] << 8));
  return std::nullopt;
}

}  // namespace

std::string_view to_string(DiscreteAction action) noexcept {
  switch (action) {
    case DiscreteAction::kOff:
      return "off";
    case DiscreteAction::kOn:
      return "on";
    case DiscreteAction::kHold:
      return "hold";
  }
  return "?";
}

std::string to_string(const AnalogAction& action) {
  switch (action.kind) {
    case AnalogAction::Kind::kHold:
      return "hold";
    case AnalogAction::Kind::kLowLimit:
      return "low limit (0 V)";
    case AnalogAction::Kind::kHighLimit:
      return "high limit (10 V)";
    case AnalogAction::Kind::kValue:
      break;
  }
  return fmt::format("{:.2f} V", raw_to_volts(action.raw));
}

std::vector<devicenet::AttributeSetting> safe_state_settings(const SafeState& safe,
                                                             SafeStateSource source,
                                                             const IoConfiguration& io) {
  std::vector<devicenet::AttributeSetting> out;
  if (io.num_digital_outputs >= 1) {
    add_discrete(out, 1, safe.pump_fault, true, source);
    add_discrete(out, 1, safe.pump_idle, false, source);
  }
  if (io.num_digital_outputs >= 2) {
    add_discrete(out, 2, safe.n2_ballast_fault, true, source);
    add_discrete(out, 2, safe.n2_ballast_idle, false, source);
  }
  if (io.num_analog_outputs >= 1) {
    add_analog(out, safe.analog_fault, true, source);
    add_analog(out, safe.analog_idle, false, source);
  }
  return out;
}

std::optional<SafeState> safe_state_in_force(std::span<const devicenet::AttributeSetting> settings,
                                             std::span<const std::vector<std::uint8_t>> values) {
  // [output][fault?]
  std::array<std::array<Read, 2>, 3> read{};
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const auto slot = slot_of(settings[i]);
    if (!slot) continue;
    if (i >= values.size()) return std::nullopt;
    const auto v = little_endian(values[i]);
    if (!v) return std::nullopt;  // not read yet, or not a size the manual gives
    Read& r = read[static_cast<std::size_t>(slot->output)][slot->fault ? 1 : 0];
    (slot->is_value ? r.value : r.action) = *v;
  }
  using O = Slot::Output;
  auto d = [&](O o, bool fault) { return discrete(read[static_cast<std::size_t>(o)][fault]); };
  auto a = [&](bool fault) { return analog(read[static_cast<std::size_t>(O::kAnalog)][fault]); };
  const auto pump_fault = d(O::kPump, true), pump_idle = d(O::kPump, false);
  const auto ballast_fault = d(O::kBallast, true), ballast_idle = d(O::kBallast, false);
  const auto analog_fault = a(true), analog_idle = a(false);
  if (!pump_fault || !pump_idle || !ballast_fault || !ballast_idle || !analog_fault ||
      !analog_idle) {
    return std::nullopt;
  }
  return SafeState{*pump_fault,   *pump_idle,    *ballast_fault,
                   *ballast_idle, *analog_fault, *analog_idle};
}

std::string describe(const SafeState& safe, const IoConfiguration& io) {
  std::string out;
  auto add = [&](std::string_view output, std::string_view fault, std::string_view idle) {
    out += fmt::format("{}{}: fault {}, idle {}", out.empty() ? "" : "; ", output, fault, idle);
  };
  if (io.num_digital_outputs >= 1)
    add("pump", to_string(safe.pump_fault), to_string(safe.pump_idle));
  if (io.num_digital_outputs >= 2)
    add("N2 ballast", to_string(safe.n2_ballast_fault), to_string(safe.n2_ballast_idle));
  if (io.num_analog_outputs >= 1)
    add("analog output", to_string(safe.analog_fault), to_string(safe.analog_idle));
  return out.empty() ? "no outputs" : out;
}

}  // namespace dnbridge::profiles::cdn127
