#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include "bridge/cip/general_status.hpp"
#include "bridge/common/time.hpp"

namespace dnbridge::devicenet {

// Life cycle of a scan-list node, as the master sees it.
enum class NodeState : std::uint8_t {
  kAbsent,              // not answering Allocate (or not tried yet)
  kIdentifying,         // allocated; reading and checking the Identity object
  kConfiguring,         // making the device's configuration match the scan list
  kVerifying,           // checking the poll connection's sizes against the configuration
  kOnline,              // polled
  kWrongDevice,         // identity differs from the scan list: never polled
  kConfigurationFault,  // device refuses the configuration, or its sizes differ
  kOwnedByOtherMaster,  // Allocate refused with 0x0C/0x01
  kStopped,             // released by an orderly shutdown, or the port stopped
  kDeviceFault,         // the device reports a major fault (Identity): released, not commanded
};

std::string_view to_string(NodeState state) noexcept;

// States in which the device is known not to be polled because of what it is
// or how it answers; re-checked periodically without leaving the state until
// the outcome changes.
constexpr bool is_fault(NodeState s) noexcept {
  return s == NodeState::kWrongDevice || s == NodeState::kConfigurationFault ||
         s == NodeState::kOwnedByOtherMaster || s == NodeState::kDeviceFault;
}

// The last thing that went wrong with a node, kept as values (no text on the
// frame path); describe() renders it.
struct NodeError {
  enum class Kind : std::uint8_t {
    kNone,
    kPollTimeout,        // no poll response before the next poll
    kPollLength,         // poll response of the wrong size (got/expected)
    kPollUnexpected,     // poll response with no poll outstanding
    kPollMalformed,      // fragmented poll response out of order
    kExplicitTimeout,    // explicit request unanswered
    kExplicitAborted,    // fragment never acknowledged
    kExplicitMalformed,  // unparsable explicit response
    kDeviceError,        // CIP error status (general/additional)
    kConnectionLost,     // silence for 4 x EPR
    kCosLength,          // change-of-state/cyclic message of the wrong size (got/expected)
    kCosUnexpected,      // change-of-state/cyclic message with no such connection
    kCosMalformed,       // fragmented change-of-state/cyclic message out of order
    kHeartbeatMissed,    // no change-of-state/cyclic message for 4 x EPR
    kStrobeLength,       // bit-strobe response of the wrong size (got/expected)
    kStrobeUnexpected,   // bit-strobe response with no bit-strobe connection
    kStrobeMissed,       // no bit-strobe response for 4 x EPR
  };
  Kind kind = Kind::kNone;
  TimePoint at{};
  std::uint32_t got = 0;
  std::uint32_t expected = 0;
  cip::GeneralStatus general_status = cip::GeneralStatus::kSuccess;
  std::uint8_t additional_status = cip::kNoAdditionalCode;

  std::string describe() const;
};

struct NodeCounters {
  std::uint64_t polls = 0;
  std::uint64_t idle_polls = 0;
  std::uint64_t responses = 0;
  std::uint64_t timeouts = 0;    // polls not answered in time
  std::uint64_t retries = 0;     // polls sent after an unanswered one
  std::uint64_t errors = 0;      // bad responses (length, order, late)
  std::uint64_t reconnects = 0;  // returns from online to allocation
  std::uint64_t allocate_attempts = 0;
  std::uint64_t idle_empty_responses = 0;  // idle polls answered with no data (valid)
  std::uint64_t explicit_retries = 0;      // life-cycle requests sent again after no answer
  std::uint64_t settings_written = 0;      // attributes the start-up had to change
  // The input connection, where the node has one: change of state or cyclic
  // (instance 4), or bit-strobe (instance 3: its responses; no acks, no
  // retries).
  std::uint64_t cos_messages = 0;       // messages taken, the device's retries included
  std::uint64_t cos_acks = 0;           // acknowledgments sent
  std::uint64_t cos_retries = 0;        // the device's retries seen (an acknowledgment it missed)
  std::uint64_t cos_errors = 0;         // messages not taken (size, order, no connection)
  std::uint64_t heartbeats_missed = 0;  // 4 x EPR without a message: the node lost
};

}  // namespace dnbridge::devicenet
