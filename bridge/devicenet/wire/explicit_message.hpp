#pragma once
// Explicit messages of the predefined master/slave connection set
// (bridge/PROTOCOL.md §2).
//
// On the wire every explicit frame starts with a header byte:
//   bit 7 Frag, bit 6 XID, bits 5..0 MAC (on Group 2 always the master's MAC).
// What follows the header (unfragmented), or the reassembled fragments, is a
// "message": the service byte (bit 7 = response) and its body.
//
// Request body:  [service][class][instance]([attribute])[service data...]
//   class/instance are 8 or 16 bits (little-endian) as the connection's body
//   format says; the attribute byte is present for Get/Set_Attribute_Single.
// Success response: [service | 0x80][service data...]
// Error response:   [0x94][general status][additional code]
#include <cstddef>
#include <cstdint>
#include <optional>

#include "bridge/can/can_frame.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::devicenet {

// Sizes of the class and instance fields of a request; the slave names the one
// that governs the connection in its Allocate response.
enum class BodyFormat : std::uint8_t {
  k8_8 = 0,    // 8-bit class, 8-bit instance
  k8_16 = 1,   // 8-bit class, 16-bit instance
  k16_16 = 2,  // 16-bit class, 16-bit instance
  k16_8 = 3,   // 16-bit class, 8-bit instance
};
// Body format 4 (packed CIP path) is not used by Group 2 only slaves; it is
// refused with Errc::kUnsupported where a format code is decoded.
Result<BodyFormat> body_format_from_code(std::uint8_t code) noexcept;

struct ExplicitHeader {
  bool frag = false;
  bool xid = false;
  MacId mac;

  friend bool operator==(const ExplicitHeader&, const ExplicitHeader&) = default;
};

std::uint8_t encode_header(ExplicitHeader h) noexcept;
ExplicitHeader decode_header(std::uint8_t byte) noexcept;

// Largest reassembled explicit message the master and the simulator handle.
inline constexpr std::size_t kMaxExplicitMessage = 512;
// Largest message sent in a single frame: 8 bytes less the header byte.
inline constexpr std::size_t kMaxUnfragmentedMessage = 7;

struct RequestMessage {
  std::uint8_t service = 0;  // without the R/R bit
  std::uint16_t class_id = 0;
  std::uint16_t instance_id = 0;
  std::optional<std::uint8_t> attribute;  // Get/Set_Attribute_Single only
  Bytes data;                             // service data, after the attribute
};

// Bytes the request takes when encoded in `format`.
std::size_t encoded_size(const RequestMessage& request, BodyFormat format) noexcept;
// Encodes into `out`; fails with kOutOfRange if class/instance do not fit the
// format or the service has the R/R bit set, kBufferTooSmall if `out` is too
// small. Returns the size written.
Result<std::size_t> encode_request(const RequestMessage& request, BodyFormat format,
                                   MutableBytes out) noexcept;
// Decodes a request message (service byte first). The attribute is read for
// the services that have one (cip::has_attribute). `data` points into `message`.
// Fails on a response (R/R set) or a truncated body.
Result<RequestMessage> decode_request(Bytes message, BodyFormat format) noexcept;

struct ResponseMessage {
  std::uint8_t service = 0;  // without the R/R bit; 0x14 for an error response
  cip::GeneralStatus general_status = cip::GeneralStatus::kSuccess;
  std::uint8_t additional_status = cip::kNoAdditionalCode;
  Bytes data;  // service data of a success response; points into the input

  bool is_error() const noexcept { return service == cip::code(cip::Service::kErrorResponse); }
};

// `service` without the R/R bit; kOutOfRange if it has it or is 0x14 (that
// would read as an error response), kBufferTooSmall if `out` is too small.
Result<std::size_t> encode_success_response(std::uint8_t service, Bytes data,
                                            MutableBytes out) noexcept;
// kOutOfRange for GeneralStatus::kSuccess (an error response must report one).
Result<std::size_t> encode_error_response(cip::GeneralStatus status, std::uint8_t additional,
                                          MutableBytes out) noexcept;
// Decodes a response message (service byte first). Fails on a request (R/R
// clear), an empty message, or an error response without its general status.
// An error response without the additional code is accepted with 0xFF; one
// whose general status is success is refused (kMalformed); bytes after the
// additional code are ignored.
Result<ResponseMessage> decode_response(Bytes message) noexcept;

// Allocation choice bits (bridge/PROTOCOL.md §3).
namespace allocation {
inline constexpr std::uint8_t kExplicit = 0x01;
inline constexpr std::uint8_t kPoll = 0x02;
inline constexpr std::uint8_t kBitStrobe = 0x04;
inline constexpr std::uint8_t kMulticastPoll = 0x08;
inline constexpr std::uint8_t kChangeOfState = 0x10;
inline constexpr std::uint8_t kCyclic = 0x20;
inline constexpr std::uint8_t kAckSuppression = 0x40;
}  // namespace allocation

// The DeviceNet object, class 3 instance 1, receives Allocate and Release.
inline constexpr std::uint8_t kDeviceNetClass = 0x03;

// Group 2 only unconnected requests, sent on Group 2 message 6 to the slave:
//   Allocate: [M][4B][03][01][choice][allocator MAC]
//   Release:  [M][4C][03][01][choice]
// Both refuse choice 0 and the reserved bit 0x80 (kOutOfRange).
Result<can::CanFrame> make_allocate_frame(MacId slave, MacId master, std::uint8_t choice) noexcept;
Result<can::CanFrame> make_release_frame(MacId slave, MacId master, std::uint8_t choice) noexcept;

// The success response to Allocate carries [reserved:4 | body format:4]. The
// reserved nibble and any bytes after the first are ignored; kTruncated when
// empty, else as body_format_from_code().
Result<BodyFormat> decode_allocate_response_data(Bytes data) noexcept;

}  // namespace dnbridge::devicenet
