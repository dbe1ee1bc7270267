#pragma once
// Duplicate MAC ID check (bridge/PROTOCOL.md §6).
//
// Message on Group 2 message 7, CAN ID 0x407 + (MAC << 3), 7 bytes:
//   [R/R:1 | physical port:7][vendor id LE:2][serial number LE:4]
// At power-up a node sends a request, listens 1 s, sends again, listens 1 s,
// then goes online. A request or response for its MAC in those windows means a
// duplicate: Communication Fault. Online it answers requests for its MAC with a
// response; a response received while online is a duplicate too.
// Frames a node sends itself must not be fed back to it (a loopback of its own
// request would read as a duplicate). When no other node acknowledges the frame
// (alone on the bus) the CAN controller keeps retransmitting it; that is below
// this layer.
#include <cstdint>
#include <optional>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/result.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

struct DuplicateMacMessage {
  bool response = false;
  std::uint8_t physical_port = 0;  // 0..127
  std::uint16_t vendor_id = 0;
  std::uint32_t serial_number = 0;

  friend bool operator==(const DuplicateMacMessage&, const DuplicateMacMessage&) = default;
};

inline constexpr std::size_t kDuplicateMacMessageSize = 7;

Result<can::CanFrame> encode_duplicate_mac(MacId mac, const DuplicateMacMessage& m) noexcept;
// Decodes the 7-byte payload; fails when shorter (kTruncated) or longer (kMalformed).
Result<DuplicateMacMessage> decode_duplicate_mac(Bytes payload) noexcept;

// The check a node makes for its own MAC, and its defence once online.
class DuplicateMacCheck {
 public:
  enum class State : std::uint8_t {
    kIdle,       // not started
    kChecking,   // requests sent, listening (two windows)
    kOnline,     // no duplicate seen; defending the MAC
    kDuplicate,  // another node has this MAC: stop (Communication Fault)
  };

  struct Config {
    Duration window = seconds(1);
    std::uint8_t physical_port = 0;  // 7 bits; higher bits are dropped
    std::uint16_t vendor_id = 0;
    std::uint32_t serial_number = 0;
  };

  DuplicateMacCheck(MacId mac, Config config) noexcept;

  // Begins (or begins again) the check; returns the first request to send.
  can::CanFrame start(TimePoint now) noexcept;
  // Call when now >= deadline(). Returns the second request when the first
  // window ends; nothing when the second ends (the node is then online).
  std::optional<can::CanFrame> on_timer(TimePoint now) noexcept;
  // A duplicate MAC message for this node's MAC (the caller filters by CAN
  // ID). Returns the response to send while online, if the message is a request.
  // Ignored before start() and once a duplicate was found.
  std::optional<can::CanFrame> on_message(const DuplicateMacMessage& m) noexcept;

  State state() const noexcept { return state_; }
  TimePoint deadline() const noexcept;
  MacId mac() const noexcept { return mac_; }

 private:
  can::CanFrame message(bool response) const noexcept;

  MacId mac_;
  Config config_;
  State state_ = State::kIdle;
  unsigned requests_sent_ = 0;
  TimePoint deadline_{};
};

}  // namespace dnbridge::devicenet
