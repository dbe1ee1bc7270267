#include "bridge/devicenet/master/node_state.hpp"

#include <fmt/format.h>

namespace dnbridge::devicenet {

std::string_view to_string(NodeState state) noexcept {
  switch (state) {
    case NodeState::kAbsent:
      return "absent";
    case NodeState::kIdentifying:
      return "identifying";
    case NodeState::kConfiguring:
      return "configuring";
    case NodeState::kVerifying:
      return "verifying";
    case NodeState::kOnline:
      return "online";
    case NodeState::kWrongDevice:
      return "wrong device";
    case NodeState::kConfigurationFault:
      return "configuration fault";
    case NodeState::kOwnedByOtherMaster:
      return "owned by another master";
    case NodeState::kStopped:
      return "stopped";
    case NodeState::kDeviceFault:
      return "device fault";
  }
  return "?";
}

std::string NodeError::describe() const {
  switch (kind) {
    case Kind::kNone:
      return "none";
    case Kind::kPollTimeout:
      return "poll response timed out";
    case Kind::kPollLength:
      return fmt::format("poll response of {} bytes, expected {}", got, expected);
    case Kind::kPollUnexpected:
      return "poll response with no poll outstanding";
    case Kind::kPollMalformed:
      return "fragmented poll response out of order";
    case Kind::kExplicitTimeout:
      return "explicit request timed out";
    case Kind::kExplicitAborted:
      return "explicit fragment not acknowledged";
    case Kind::kExplicitMalformed:
      return "malformed explicit response";
    case Kind::kDeviceError: {
      auto name = cip::to_string(general_status);
      return fmt::format("device error 0x{:02X}/0x{:02X} ({})",
                         static_cast<unsigned>(general_status), additional_status,
                         name.empty() ? "reserved" : name);
    }
    case Kind::kConnectionLost:
      return "connection lost: no poll response for 4 x EPR";
    case Kind::kCosLength:
      return fmt::format("change-of-state message of {} bytes, expected {}", got, expected);
    case Kind::kCosUnexpected:
      return "change-of-state message with no change-of-state connection";
    case Kind::kCosMalformed:
      return "fragmented change-of-state message out of order";
    case Kind::kHeartbeatMissed:
      return "connection lost: no change-of-state message for 4 x EPR";
    case Kind::kStrobeLength:
      return fmt::format("bit-strobe response of {} bytes, expected {}", got, expected);
    case Kind::kStrobeUnexpected:
      return "bit-strobe response with no bit-strobe connection";
    case Kind::kStrobeMissed:
      return "connection lost: no bit-strobe response for 4 x EPR";
  }
  return "?";
}

}  // namespace dnbridge::devicenet
