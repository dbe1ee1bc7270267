#pragma once
// The Group 4 Offline Connection Set (bridge/PROTOCOL.md §9; CDN127 manual,
// "DeviceNet Message Types"): lets a tool reach a node stuck in Communication
// Fault (e.g. after a duplicate MAC) without a power cycle, naming it by vendor
// ID + serial number, and change its MAC.
//
//   0x7EC Communication Faulted Response   0x7ED Communication Faulted Request
//   0x7EE Offline Ownership Response       0x7EF Offline Ownership Request
//
// UNVERIFIED as a whole: the ODVA text (CIP Vol 3, "Offline Connection Set")
// was not available. The layouts are those Wireshark's DeviceNet dissector
// parses (epan/dissectors/packet-devicenet.c, which cites CIP Vol 3 edition
// 1.14), widened where a vendor manual shows other frames (ICP DAS I-7242D
// user manual, 2006, §7.2.10). The forms differ in length, so one decoder
// accepts all of them:
//
// Communication Faulted request/response, by length:
//   2  kShort             [rsv b7 | match b6 | value b5..0][R/R b7 | service b6..0]
//                         (Wireshark)
//   3  kShortWithDelay    kShort + [time delay byte offset]
//                         (ICP DAS: request "3F 4B 02", match 0, value 0x3F, service 0x4B)
//   7  kPortVendorSerial  [physical port][vendor LE:2][serial LE:4]; a response only
//                         (ICP DAS: response "00 23 03 01 00 00 00"; Wireshark
//                         shows nothing for this length)
//   8  kLong              [rsv b7 | match b6 | value b5..0][R/R | service][vendor LE:2][serial
//   LE:4]
//                         (Wireshark, which names only bit 7 of the first byte
//                         "reserved" and leaves bits 6..0 unparsed; this codec
//                         reads them as in the short form, and a Set MAC
//                         request carries the new MAC in value)
// Offline Ownership request/response, 8 bytes (Wireshark):
//   [rsv b7..6 | client MAC b5..0][R/R b7 | allocate b6..0][vendor LE:2][serial LE:4]
//
// Meanings no source states and this project assumes (each one a choice of
// the simulator's options where it matters):
// - match = 1: only the node whose MAC equals value answers; match = 0: every
//   faulted node answers (value is 6 bits wide, a MAC; the ICP DAS example
//   sends match 0 with value 0x3F to find any node).
// - allocate = 1 takes ownership, 0 gives it up.
// - whose vendor/serial the ownership messages carry (the addressed node's or
//   the client's): see OwnershipIdentity.
// Reserved bits are ignored on decode and written as 0.
#include <cstddef>
#include <cstdint>

#include "bridge/can/can_frame.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

// The service of the "who is communication faulted" request in the ICP DAS
// example (request "3F 4B 02").
inline constexpr std::uint8_t kCommFaultedIdentifyService = 0x4B;

enum class CommFaultedLayout : std::uint8_t {
  kShort,             // 2 bytes
  kShortWithDelay,    // 3 bytes
  kPortVendorSerial,  // 7 bytes, response only
  kLong,              // 8 bytes
};

struct CommFaultedMessage {
  CommFaultedLayout layout = CommFaultedLayout::kShort;
  // R/R bit. The 7-byte layout has none and is always a response.
  bool response = false;
  bool match = false;                  // short and long layouts
  std::uint8_t value = 0;              // 0..63; short and long layouts
  std::uint8_t service = 0;            // 0..127; all but the 7-byte layout
  std::uint8_t delay_byte_offset = 0;  // kShortWithDelay only
  std::uint8_t physical_port = 0;      // 0..127; kPortVendorSerial only
  std::uint16_t vendor_id = 0;         // 7- and 8-byte layouts
  std::uint32_t serial_number = 0;     // 7- and 8-byte layouts

  friend bool operator==(const CommFaultedMessage&, const CommFaultedMessage&) = default;
};

// Payload bytes of a layout.
std::size_t comm_faulted_size(CommFaultedLayout layout) noexcept;

// Fields a layout does not carry are not encoded. CAN ID 0x7EC for responses
// (the 7-byte layout always), 0x7ED for requests. kOutOfRange for a value
// over 63, a service or port over 127.
Result<can::CanFrame> encode_comm_faulted(const CommFaultedMessage& m) noexcept;
// Picks the layout by length: 2, 3, 7 or 8 bytes. Shorter than 2 or between
// 4 and 6: kTruncated; longer than 8: kMalformed. Fields the layout does not
// carry are left 0.
Result<CommFaultedMessage> decode_comm_faulted(Bytes payload) noexcept;

struct OfflineOwnershipMessage {
  bool response = false;
  MacId client_mac{};
  std::uint8_t allocate = 0;  // 0..127: 1 take ownership, 0 give it up
  std::uint16_t vendor_id = 0;
  std::uint32_t serial_number = 0;

  friend bool operator==(const OfflineOwnershipMessage&, const OfflineOwnershipMessage&) = default;
};

inline constexpr std::size_t kOfflineOwnershipSize = 8;
inline constexpr std::uint8_t kOfflineAllocate = 1;
inline constexpr std::uint8_t kOfflineRelease = 0;

// Whose vendor ID and serial number the Offline Ownership messages carry.
// Wireshark labels the MAC "Client MAC ID" but the vendor and serial with the
// same generic fields it uses in the Communication Faulted long form, where
// they name the faulted node; no source says which.
enum class OwnershipIdentity : std::uint8_t {
  kTarget,  // the node the client takes ownership of: only it answers
  kClient,  // the client's own: every faulted, unowned node answers
};

// CAN ID 0x7EE for a response, 0x7EF for a request. kOutOfRange for an
// allocate field over 127.
Result<can::CanFrame> encode_offline_ownership(const OfflineOwnershipMessage& m) noexcept;
// Exactly 8 bytes: shorter kTruncated, longer kMalformed.
Result<OfflineOwnershipMessage> decode_offline_ownership(Bytes payload) noexcept;

}  // namespace dnbridge::devicenet
