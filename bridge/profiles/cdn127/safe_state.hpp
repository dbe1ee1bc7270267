#pragma once
// What a CDN127's outputs do when its master stops (a fault: the poll
// connection timed out) and when its master polls idle (zero-length polls):
// the Discrete Output Point instances' attributes 5..8 (1 the pump, 2 the N2
// ballast) and the Analog Output Point's attributes 9..12. The configuration
// says them in words; the master downloads them during start-up and reads
// them back, before the poll connection exists.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::profiles::cdn127 {

// A discrete output's action: switched off, switched on, or left as it is.
enum class DiscreteAction : std::uint8_t { kOff, kOn, kHold };

// The analog output's action (AOP Fault/Idle State 0..3).
struct AnalogAction {
  enum class Kind : std::uint8_t { kHold, kLowLimit, kHighLimit, kValue };
  Kind kind = Kind::kValue;
  std::uint16_t raw = 0;  // kValue: 0..4095

  friend bool operator==(const AnalogAction&, const AnalogAction&) = default;
};

struct SafeState {
  DiscreteAction pump_fault = DiscreteAction::kOff;
  DiscreteAction pump_idle = DiscreteAction::kOff;
  DiscreteAction n2_ballast_fault = DiscreteAction::kOff;
  DiscreteAction n2_ballast_idle = DiscreteAction::kOff;
  AnalogAction analog_fault{};
  AnalogAction analog_idle{};

  friend bool operator==(const SafeState&, const SafeState&) = default;
};

// Where the safe state in force comes from.
enum class SafeStateSource : std::uint8_t {
  kConfiguration,  // downloaded by the master and read back
  kDevice,         // the device's own, read and kept (safe_state = "device")
};

std::string_view to_string(DiscreteAction action) noexcept;  // "off", "on", "hold"
std::string to_string(const AnalogAction& action);           // "hold", "2.50 V", ...

// The node-profile settings of `safe` for the outputs `io` has (DOP instance
// n when it has n digital outputs or more; the AOP when it has an analog
// output): the action, and the value where the action uses one. With
// kDevice every attribute is read and none written.
std::vector<devicenet::AttributeSetting> safe_state_settings(const SafeState& safe,
                                                             SafeStateSource source,
                                                             const IoConfiguration& io);

// The safe state the device has, from the values the master read for the
// profile's settings (Node::settings_in_force; index as in `settings`).
// Nothing until every safe-state setting has been read; an output the
// configuration leaves out keeps kOff / 0 V. Values of a size or range the
// manual does not give make it nothing too.
std::optional<SafeState> safe_state_in_force(std::span<const devicenet::AttributeSetting> settings,
                                             std::span<const std::vector<std::uint8_t>> values);

// "pump: fault off, idle off; N2 ballast: fault off, idle off; analog
// output: fault 0.00 V, idle 0.00 V", for the outputs `io` has.
std::string describe(const SafeState& safe, const IoConfiguration& io);

}  // namespace dnbridge::profiles::cdn127
