#include "adapters/dds/states.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace dnbridge::dds {
namespace {

using devicenet::NodeState;
using devicenet::PortState;
using port::BusState;

constexpr std::array<std::pair<NodeState, dnbridge_NodeLifecycle>, 10> kNodeStates{{
    {NodeState::kAbsent, dnbridge_NODE_ABSENT},
    {NodeState::kIdentifying, dnbridge_NODE_IDENTIFYING},
    {NodeState::kConfiguring, dnbridge_NODE_CONFIGURING},
    {NodeState::kVerifying, dnbridge_NODE_VERIFYING},
    {NodeState::kOnline, dnbridge_NODE_ONLINE},
    {NodeState::kWrongDevice, dnbridge_NODE_WRONG_DEVICE},
    {NodeState::kConfigurationFault, dnbridge_NODE_CONFIGURATION_FAULT},
    {NodeState::kOwnedByOtherMaster, dnbridge_NODE_OWNED_BY_OTHER_MASTER},
    {NodeState::kStopped, dnbridge_NODE_STOPPED},
    {NodeState::kDeviceFault, dnbridge_NODE_DEVICE_FAULT},
}};

constexpr std::array<std::pair<PortState, dnbridge_PortLifecycle>, 5> kPortStates{{
    {PortState::kStopped, dnbridge_PORT_STOPPED},
    {PortState::kCheckingMac, dnbridge_PORT_CHECKING_MAC},
    {PortState::kRunning, dnbridge_PORT_RUNNING},
    {PortState::kStopping, dnbridge_PORT_STOPPING},
    {PortState::kDuplicateMac, dnbridge_PORT_DUPLICATE_MAC},
}};

constexpr std::array<std::pair<BusState, dnbridge_BusState>, 6> kBusStates{{
    {BusState::kErrorActive, dnbridge_BUS_ERROR_ACTIVE},
    {BusState::kErrorWarning, dnbridge_BUS_ERROR_WARNING},
    {BusState::kErrorPassive, dnbridge_BUS_ERROR_PASSIVE},
    {BusState::kBusOff, dnbridge_BUS_OFF},
    {BusState::kUnknown, dnbridge_BUS_STATE_UNKNOWN},
    {BusState::kDown, dnbridge_BUS_DOWN},
}};

using DiscreteAction = profiles::cdn127::DiscreteAction;
using AnalogKind = profiles::cdn127::AnalogAction::Kind;

constexpr std::array<std::pair<DiscreteAction, dnbridge_SafeAction>, 3> kDiscreteActions{{
    {DiscreteAction::kOff, dnbridge_SAFE_ACTION_OFF},
    {DiscreteAction::kOn, dnbridge_SAFE_ACTION_ON},
    {DiscreteAction::kHold, dnbridge_SAFE_ACTION_HOLD},
}};

constexpr std::array<std::pair<AnalogKind, dnbridge_SafeAction>, 4> kAnalogActions{{
    {AnalogKind::kLowLimit, dnbridge_SAFE_ACTION_OFF},
    {AnalogKind::kHighLimit, dnbridge_SAFE_ACTION_ON},
    {AnalogKind::kHold, dnbridge_SAFE_ACTION_HOLD},
    {AnalogKind::kValue, dnbridge_SAFE_ACTION_VALUE},
}};

using devicenet::ScanOutcome;

constexpr std::array<std::pair<ScanOutcome, std::uint8_t>, 6> kScanOutcomes{{
    {ScanOutcome::kIdentified, dnbridge_FOUND_IDENTIFIED},
    {ScanOutcome::kNoAnswer, dnbridge_FOUND_NO_ANSWER},
    {ScanOutcome::kRefused, dnbridge_FOUND_REFUSED},
    {ScanOutcome::kOwnedByOtherMaster, dnbridge_FOUND_OWNED_BY_OTHER_MASTER},
    {ScanOutcome::kAnsweringOtherMaster, dnbridge_FOUND_ANSWERING_OTHER_MASTER},
    {ScanOutcome::kNotAsked, dnbridge_FOUND_NOT_ASKED},
}};

template <class Table, class Core>
auto idl_of(const Table& table, Core core, decltype(table[0].second) otherwise) {
  const auto it = std::find_if(table.begin(), table.end(),
                               [core](const auto& entry) { return entry.first == core; });
  return it == table.end() ? otherwise : it->second;
}

template <class Table, class Idl>
auto core_of(const Table& table, Idl idl) -> std::optional<decltype(table[0].first)> {
  const auto it = std::find_if(table.begin(), table.end(),
                               [idl](const auto& entry) { return entry.second == idl; });
  if (it == table.end()) return std::nullopt;
  return it->first;
}

}  // namespace

dnbridge_NodeLifecycle to_idl(NodeState state) {
  return idl_of(kNodeStates, state, dnbridge_NODE_ABSENT);
}
dnbridge_PortLifecycle to_idl(PortState state) {
  return idl_of(kPortStates, state, dnbridge_PORT_STOPPED);
}
dnbridge_BusState to_idl(BusState state) {
  return idl_of(kBusStates, state, dnbridge_BUS_STATE_UNKNOWN);
}

dnbridge_SafeAction to_idl(DiscreteAction action) {
  return idl_of(kDiscreteActions, action, dnbridge_SAFE_ACTION_UNKNOWN);
}
dnbridge_SafeAction to_idl(const profiles::cdn127::AnalogAction& action) {
  return idl_of(kAnalogActions, action.kind, dnbridge_SAFE_ACTION_UNKNOWN);
}

std::optional<NodeState> from_idl(dnbridge_NodeLifecycle state) {
  return core_of(kNodeStates, state);
}
std::optional<PortState> from_idl(dnbridge_PortLifecycle state) {
  return core_of(kPortStates, state);
}
std::optional<BusState> from_idl(dnbridge_BusState state) { return core_of(kBusStates, state); }

std::string_view name_of(dnbridge_NodeLifecycle state) {
  const auto core = from_idl(state);
  return core ? devicenet::to_string(*core) : "unknown";
}
std::string_view name_of(dnbridge_PortLifecycle state) {
  const auto core = from_idl(state);
  return core ? devicenet::to_string(*core) : "unknown";
}
std::string_view name_of(dnbridge_BusState state) {
  const auto core = from_idl(state);
  return core ? port::to_string(*core) : "unknown";
}

std::string_view name_of(dnbridge_SafeAction action) {
  if (const auto core = core_of(kDiscreteActions, action)) {
    return profiles::cdn127::to_string(*core);
  }
  return action == dnbridge_SAFE_ACTION_VALUE ? "value" : "unknown";
}

std::uint8_t found_to_idl(devicenet::ScanOutcome outcome) {
  return idl_of(kScanOutcomes, outcome, dnbridge_FOUND_NOT_ASKED);
}

std::optional<devicenet::ScanOutcome> found_from_idl(std::uint8_t found) {
  return core_of(kScanOutcomes, found);
}

std::string_view found_name(std::uint8_t found) {
  if (const auto core = found_from_idl(found)) return devicenet::to_string(*core);
  return "unknown";
}

}  // namespace dnbridge::dds
