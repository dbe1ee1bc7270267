#pragma once
// DeviceNet use of the 11-bit CAN identifier (bridge/PROTOCOL.md §1):
//   Group 1: 0 mmmm ssssss     0x000-0x3FF   message id 0..15, source MAC
//   Group 2: 1 0 MMMMMM iii    0x400-0x5FF   MAC, message id 0..7
//   Group 3: 1 1 iii ssssss    0x600-0x7BF   message id 0..6, source MAC
//   Group 4: 11111 iiiiii      0x7C0-0x7EF   message id 0x00..0x2F
//   0x7F0-0x7FF are invalid.
#include <cstdint>

#include "bridge/common/result.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

enum class MessageGroup : std::uint8_t { k1 = 1, k2 = 2, k3 = 3, k4 = 4 };

struct Identifier {
  MessageGroup group = MessageGroup::k1;
  std::uint8_t message_id = 0;  // meaning depends on the group
  MacId mac;                    // unused in Group 4

  friend bool operator==(const Identifier&, const Identifier&) = default;
};

Result<Identifier> decode_identifier(std::uint32_t can_id) noexcept;
Result<std::uint32_t> encode_identifier(const Identifier& id) noexcept;

// Messages of the predefined master/slave connection set.
enum class Group1Message : std::uint8_t {
  kSlaveMulticastPollResponse = 0xC,
  kSlaveCosCyclic = 0xD,
  kSlaveBitStrobeResponse = 0xE,
  kSlavePollResponse = 0xF,  // also the slave's ack of a master COS/cyclic message
};

enum class Group2Message : std::uint8_t {
  kMasterBitStrobeCommand = 0,      // MAC = source (master)
  kMasterMulticastPoll = 1,         // MAC field use UNVERIFIED
  kMasterCosCyclicAck = 2,          // MAC = destination
  kSlaveExplicitResponse = 3,       // MAC = source (slave); also unconnected responses
  kMasterExplicitRequest = 4,       // MAC = destination
  kMasterIoPoll = 5,                // MAC = destination; also master COS/cyclic
  kUnconnectedExplicitRequest = 6,  // MAC = destination; Group 2 only Allocate/Release
  kDuplicateMacCheck = 7,           // MAC = the MAC being checked
};

enum class Group4Message : std::uint8_t {
  kCommFaultedResponse = 0x2C,
  kCommFaultedRequest = 0x2D,
  kOfflineOwnershipResponse = 0x2E,
  kOfflineOwnershipRequest = 0x2F,
};

constexpr std::uint32_t group1_id(Group1Message m, MacId source) noexcept {
  return (static_cast<std::uint32_t>(m) << 6) | source.value();
}
constexpr std::uint32_t group2_id(MacId mac, Group2Message m) noexcept {
  return 0x400u | (static_cast<std::uint32_t>(mac.value()) << 3) | static_cast<std::uint32_t>(m);
}
constexpr std::uint32_t group4_id(Group4Message m) noexcept {
  return 0x7C0u | static_cast<std::uint32_t>(m);
}

}  // namespace dnbridge::devicenet
