#pragma once
// Decoders for the device-information attributes a master reads from a CDN127
// by explicit messaging (Get_Attribute_Single response data): Identity
// (class 0x01) revision, status, serial number, product name and state;
// Device Supervisor (class 0x32) device status, exception status, exception
// and warning detail.
//
// Every decoder takes the whole attribute value and fails with kTruncated
// when it ends early and kMalformed when bytes are left over. Values the
// manual does not name (reserved states, reserved status bits) are kept, not
// refused: the master reports what the device says.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"

namespace dnbridge::profiles::cdn127 {

// Identity attribute 4: STRUCT of major, minor revision (USINT each).
struct Revision {
  std::uint8_t major = 0;
  std::uint8_t minor = 0;
  friend bool operator==(const Revision&, const Revision&) = default;
};
Result<Revision> decode_revision(Bytes value) noexcept;

// Identity attribute 5, a WORD. Bit meanings per the ODVA Identity object; the
// CDN127 manual lists bits 8 and 9 twice (see device_info.cpp).
struct IdentityStatus {
  std::uint16_t raw = 0;

  bool owned() const noexcept { return (raw & 0x0001U) != 0; }       // bit 0
  bool configured() const noexcept { return (raw & 0x0004U) != 0; }  // bit 2 (CDN127: unsupported)
  std::uint8_t user_defined() const noexcept {                       // bits 4..7
    return static_cast<std::uint8_t>((raw >> 4) & 0x0FU);
  }
  bool minor_recoverable_fault() const noexcept { return (raw & 0x0100U) != 0; }    // bit 8
  bool minor_unrecoverable_fault() const noexcept { return (raw & 0x0200U) != 0; }  // bit 9
  bool major_recoverable_fault() const noexcept { return (raw & 0x0400U) != 0; }    // bit 10
  bool major_unrecoverable_fault() const noexcept { return (raw & 0x0800U) != 0; }  // bit 11
  bool any_fault() const noexcept { return (raw & 0x0F00U) != 0; }
  friend bool operator==(const IdentityStatus&, const IdentityStatus&) = default;
};
Result<IdentityStatus> decode_identity_status(Bytes value) noexcept;

// Identity attribute 6. The CDN127 manual types it UINT, the ODVA Identity
// object UDINT; either width is accepted and remembered.
struct SerialNumber {
  std::uint32_t value = 0;
  std::uint8_t width = 4;  // bytes the device sent: 2 or 4
  friend bool operator==(const SerialNumber&, const SerialNumber&) = default;
};
Result<SerialNumber> decode_serial_number(Bytes value) noexcept;

// A SHORT_STRING (1-byte length, then that many ISO 8859-1 characters): the
// Identity product name (attribute 7) and the Device Supervisor's SSTRING
// attributes 3..8. No heap: the characters live inline.
class ShortString {
 public:
  static constexpr std::size_t kMaxLength = 255;
  std::string_view view() const noexcept { return {chars_.data(), length_}; }
  std::size_t size() const noexcept { return length_; }
  friend bool operator==(const ShortString& a, const ShortString& b) noexcept {
    return a.view() == b.view();
  }

 private:
  friend Result<ShortString> decode_short_string(Bytes value) noexcept;
  std::array<char, kMaxLength> chars_{};
  std::size_t length_ = 0;
};
Result<ShortString> decode_short_string(Bytes value) noexcept;
inline Result<ShortString> decode_product_name(Bytes value) noexcept {
  return decode_short_string(value);
}

// Identity attribute 8 (manual, "Device State – Attribute 8"). Other values
// (reserved in the ODVA object; 255 is its "default") decode as themselves.
enum class IdentityState : std::uint8_t {
  kNonExistent = 0,
  kSelfTest = 1,
  kStandby = 2,
  kOperating = 3,
  kMajorRecoverableFault = 4,    // CDN127: loss of +24 Vdc power
  kMajorUnrecoverableFault = 5,  // CDN127: memory checksum failure
};
Result<IdentityState> decode_identity_state(Bytes value) noexcept;
std::string_view to_string(IdentityState state) noexcept;  // "reserved" when unnamed

// Device Supervisor "Device Status" (attribute 11 in its table; the text says
// 9). 7..50 reserved, 51..99 device specific, 100..255 vendor specific.
enum class SupervisorDeviceStatus : std::uint8_t {
  kUndefined = 0,
  kSelfTesting = 1,
  kIdle = 2,
  kSelfTestException = 3,
  kExecuting = 4,
  kAbort = 5,
  kCriticalFault = 6,
};
Result<SupervisorDeviceStatus> decode_supervisor_device_status(Bytes value) noexcept;
// Names 0..6; otherwise "reserved", "device specific" or "vendor specific".
std::string_view to_string(SupervisorDeviceStatus status) noexcept;

// Device Supervisor attribute 12 (one byte; bit meanings in io_data.hpp).
Result<ExceptionStatus> decode_exception_status(Bytes value) noexcept;

// Bit-packed status of one kind of I/O point (DIP, DOP, AIP, AOP) inside the
// device detail: a USINT count of status bits, then (count + 7) / 8 bytes.
struct PointStatus {
  static constexpr std::size_t kMaxBytes = (255 + 7) / 8;
  std::uint8_t count = 0;                      // status bits (number of points)
  std::array<std::uint8_t, kMaxBytes> bits{};  // (count + 7) / 8 bytes are used
  // Status bit of point `index` (0-based: instance index + 1); false past count.
  bool fault(std::size_t index) const noexcept {
    return index < count && ((static_cast<unsigned>(bits[index / 8]) >> (index % 8)) & 1U) != 0;
  }
  bool any_fault() const noexcept;
  friend bool operator==(const PointStatus&, const PointStatus&) = default;
};

// A size-prefixed block of detail bytes (common and manufacturer detail).
using DetailBytes = InlineBytes<255>;

// Device Supervisor attribute 13 (Exception Detail) or 14 (Warning Detail):
//   Common Detail:       Size USINT, Detail BYTE[Size]
//   Device Detail:       Size USINT, then Size bytes holding, in order, the
//                        DIP, DOP, AIP and AOP point status structures
//   Manufacturer Detail: Size USINT, Detail BYTE[Size]
// Sizes are taken from the device, not from the manual's table (2, 8, 1 for the
// exception detail; 2, 0, 1 for the warning detail).
struct SupervisorDetail {
  enum Point : std::size_t { kDip = 0, kDop = 1, kAip = 2, kAop = 3 };

  DetailBytes common;
  std::uint8_t device_size = 0;  // as sent
  // How many of the point structures the device detail held (0..4, in order
  // DIP, DOP, AIP, AOP); a warning detail holds none.
  std::size_t point_count = 0;
  std::array<PointStatus, 4> points{};
  DetailBytes device_extra;  // device detail bytes after the fourth structure
  DetailBytes manufacturer;
};
// kTruncated if a size runs past the end of `value`; kMalformed if a point
// structure runs past the end of its device detail, or bytes follow the
// manufacturer detail.
Result<SupervisorDetail> decode_supervisor_detail(Bytes value) noexcept;
inline Result<SupervisorDetail> decode_exception_detail(Bytes value) noexcept {
  return decode_supervisor_detail(value);
}
inline Result<SupervisorDetail> decode_warning_detail(Bytes value) noexcept {
  return decode_supervisor_detail(value);
}

}  // namespace dnbridge::profiles::cdn127
