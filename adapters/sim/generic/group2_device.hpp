#pragma once
// What the wire of a simulated Group 2 only slave (group2_slave.hpp) and the
// device behind it exchange: how the device starts up, what a request leaves
// to do once answered, what a poll command came to, and the choices the
// device makes on the Offline Connection Set.
#include <cstdint>

#include "bridge/common/bytes.hpp"
#include "bridge/devicenet/wire/offline_connection.hpp"

namespace dnbridge::sim {

// The Group 4 Offline Connection Set (bridge/PROTOCOL.md §9, UNVERIFIED; layouts
// and sources in bridge/devicenet/wire/offline_connection.hpp). Where the sources
// disagree or are silent, the choice is here.
struct OfflineOptions {
  // The CDN127 manual ("DeviceNet Message Types") lists the set as supported.
  bool supported = true;
  // Layout of the answer to an identify request: Wireshark's 8-byte form
  // [match/value][R/R | service][vendor][serial] (value = the node's MAC), or
  // the ICP DAS manual's 7-byte [port][vendor][serial].
  devicenet::CommFaultedLayout identify_response = devicenet::CommFaultedLayout::kLong;
  devicenet::OwnershipIdentity ownership_identity = devicenet::OwnershipIdentity::kTarget;
  // The identify service is the ICP DAS example's. No source gives the
  // service that sets the MAC offline: Set_Attribute_Single (the DeviceNet
  // object's MAC ID attribute, implied), the new MAC in the value field of a
  // long-form request that names the node by vendor and serial.
  std::uint8_t identify_service = devicenet::kCommFaultedIdentifyService;
  std::uint8_t set_mac_service = 0x10;
};

// What starts the device up: power applied, which ends unrecoverable faults,
// or a restart with power on (Identity Reset, a new MAC), which does not.
enum class PowerUpCause : std::uint8_t { kPowerOn, kRestart };

// Work to do once the response to the current request has been sent.
enum class PendingAction : std::uint8_t {
  kNone,
  kRestart,                 // Identity Reset type 0, or a new MAC: re-enter the network
  kRestartFactoryDefaults,  // Identity Reset type 1
};

enum class PollOutcome : std::uint8_t {
  kNotEstablished,  // ignored: no established poll connection
  kOversize,        // ignored: longer than the consumed size
  kApplied,         // outputs updated, response built
  kIdle,            // shorter than the consumed size: idle actions, response built
                    // (empty where the device answers an idle poll so)
  kInvalid,         // full size but a value the device refuses: outputs kept, response built
  kMajorFault,      // a major fault stands: outputs kept in their fault state, response
                    // built (empty for an idle poll where the device answers it so)
};

// I/O messages are not fragmented here: the produced data fits one frame.
inline constexpr std::size_t kMaxPollData = 8;

struct PollResult {
  PollOutcome outcome = PollOutcome::kNotEstablished;
  InlineBytes<kMaxPollData> response;  // the produced data, when outcome is not an ignore
};

}  // namespace dnbridge::sim
