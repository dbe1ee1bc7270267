#pragma once
// The data model's state enums and the bridge's own, one table per enum
// (states.cpp) for both directions; and one name per state, the core's,
// which the logs, dnbctl's text and its JSON all use.
#include <cstdint>
#include <optional>
#include <string_view>

#include "adapters/port/can_backend.hpp"
#include "bridge/devicenet/master/node_state.hpp"
#include "bridge/devicenet/master/scanner_events.hpp"
#include "bridge/profiles/cdn127/safe_state.hpp"
#include "dnbridge.h"

namespace dnbridge::dds {

dnbridge_NodeLifecycle to_idl(devicenet::NodeState state);
dnbridge_PortLifecycle to_idl(devicenet::PortState state);
dnbridge_BusState to_idl(port::BusState state);
// A safe state's actions: the discrete outputs' off/on/hold; the analog
// output's low limit as OFF, high limit as ON, a value as VALUE.
dnbridge_SafeAction to_idl(profiles::cdn127::DiscreteAction action);
dnbridge_SafeAction to_idl(const profiles::cdn127::AnalogAction& action);

// nullopt: a value this program does not know (a newer bridge's).
std::optional<devicenet::NodeState> from_idl(dnbridge_NodeLifecycle state);
std::optional<devicenet::PortState> from_idl(dnbridge_PortLifecycle state);
std::optional<port::BusState> from_idl(dnbridge_BusState state);

// "online", "owned by another master", ...; "unknown" for a value not known.
std::string_view name_of(dnbridge_NodeLifecycle state);
// "running", "duplicate MAC", ...
std::string_view name_of(dnbridge_PortLifecycle state);
// "error-active", "bus-off", "interface down", ...
std::string_view name_of(dnbridge_BusState state);
// "off", "on", "hold" (the core's), "value", "unknown".
std::string_view name_of(dnbridge_SafeAction action);

// A bus scan finding's FOUND_* value (an octet constant, not an enum).
std::uint8_t found_to_idl(devicenet::ScanOutcome outcome);
std::optional<devicenet::ScanOutcome> found_from_idl(std::uint8_t found);
// "identified", "no answer", ... (the core's); "unknown".
std::string_view found_name(std::uint8_t found);

}  // namespace dnbridge::dds
