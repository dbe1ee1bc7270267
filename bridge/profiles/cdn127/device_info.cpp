// Device-information attributes of the CDN127 Identity and Device Supervisor
// objects (manual, "Identity Object" and "Device Supervisor Object").
#include "bridge/profiles/cdn127/device_info.hpp"

namespace dnbridge::profiles::cdn127 {

namespace {
// A fixed-size attribute: exactly `size` bytes.
Status check_size(Bytes value, std::size_t size) noexcept {
  if (value.size() < size) return Errc::kTruncated;
  if (value.size() > size) return Errc::kMalformed;
  return {};
}
}  // namespace

// "Revision Information – Attribute 4": major then minor revision.
Result<Revision> decode_revision(Bytes value) noexcept {
  if (Status s = check_size(value, 2); !s) return s.error();
  ByteReader r{value};
  Revision rev;
  rev.major = r.u8();
  rev.minor = r.u8();
  return rev;
}

// "Device Status – Attribute 5" lists "8 Minor Recoverable fault", "9 Minor
// Unrecoverable fault", then "8 Major Recoverable fault ... (Loss of +24 Vdc)"
// and "9 Major Unrecoverable fault ... (Checksum, A/D)", and "12-15 Reserved".
// Bits 10 and 11 are missing and 8/9 are listed twice; the ODVA Identity
// object puts the major faults at 10 and 11, which is the only reading that
// gives every fault its own bit and leaves 12..15 as the reserved bits the
// manual names. The raw word is kept, so no bit is lost.
Result<IdentityStatus> decode_identity_status(Bytes value) noexcept {
  if (Status s = check_size(value, 2); !s) return s.error();
  ByteReader r{value};
  return IdentityStatus{.raw = r.u16le()};
}

// "Serial Number – Attribute 6" is typed UINT in the manual's table; the ODVA
// Identity object, and the duplicate MAC ID check message, carry a UDINT.
Result<SerialNumber> decode_serial_number(Bytes value) noexcept {
  ByteReader r{value};
  switch (value.size()) {
    case 2:
      return SerialNumber{.value = r.u16le(), .width = 2};
    case 4:
      return SerialNumber{.value = r.u32le(), .width = 4};
    case 0:
    case 1:
    case 3:
      return Errc::kTruncated;
    default:
      return Errc::kMalformed;
  }
}

Result<ShortString> decode_short_string(Bytes value) noexcept {
  ByteReader r{value};
  const std::uint8_t length = r.u8();
  const Bytes chars = r.bytes(length);
  if (!r.ok()) return Errc::kTruncated;
  if (!r.at_end()) return Errc::kMalformed;
  ShortString s;
  for (std::size_t i = 0; i < chars.size(); ++i) s.chars_[i] = static_cast<char>(chars[i]);
  s.length_ = chars.size();
  return s;
}

Result<IdentityState> decode_identity_state(Bytes value) noexcept {
  if (Status s = check_size(value, 1); !s) return s.error();
  return static_cast<IdentityState>(value[0]);
}

std::string_view to_string(IdentityState state) noexcept {
  switch (state) {
    case IdentityState::kNonExistent:
      return "non-existent";
    case IdentityState::kSelfTest:
      return "self test";
    case IdentityState::kStandby:
      return "standby";
    case IdentityState::kOperating:
      return "operating";
    case IdentityState::kMajorRecoverableFault:
      return "major recoverable fault";
    case IdentityState::kMajorUnrecoverableFault:
      return "major unrecoverable fault";
  }
  return "reserved";
}

Result<SupervisorDeviceStatus> decode_supervisor_device_status(Bytes value) noexcept {
  if (Status s = check_size(value, 1); !s) return s.error();
  return static_cast<SupervisorDeviceStatus>(value[0]);
}

std::string_view to_string(SupervisorDeviceStatus status) noexcept {
  switch (status) {
    case SupervisorDeviceStatus::kUndefined:
      return "undefined";
    case SupervisorDeviceStatus::kSelfTesting:
      return "self testing";
    case SupervisorDeviceStatus::kIdle:
      return "idle";
    case SupervisorDeviceStatus::kSelfTestException:
      return "self-test exception";
    case SupervisorDeviceStatus::kExecuting:
      return "executing";
    case SupervisorDeviceStatus::kAbort:
      return "abort";
    case SupervisorDeviceStatus::kCriticalFault:
      return "critical fault";
  }
  // Manual: "7-50 Reserved", "51-99 Device Specific", "100-255 Vendor Specific".
  const auto v = static_cast<std::uint8_t>(status);
  if (v <= 50) return "reserved";
  if (v <= 99) return "device specific";
  return "vendor specific";
}

Result<ExceptionStatus> decode_exception_status(Bytes value) noexcept {
  if (Status s = check_size(value, 1); !s) return s.error();
  return ExceptionStatus::decode(value[0]);
}

bool PointStatus::any_fault() const noexcept {
  for (std::size_t i = 0; i < count; ++i) {
    if (fault(i)) return true;
  }
  return false;
}

namespace {
// A Size USINT and that many bytes.
bool read_sized_block(ByteReader& r, DetailBytes& out) noexcept {
  const std::uint8_t size = r.u8();
  const Bytes block = r.bytes(size);
  return r.ok() && out.assign(block);
}
}  // namespace

// Device Supervisor attributes 13/14. The manual's table for attribute 13:
// Common Detail (Size 2, Detail BYTE[2]); Device Detail (Device Size 8, then
// DIP, DOP, AIP and AOP Status, each "Number" USINT and the status BYTE); Man.
// Detail (Size 1, Detail). "Number of bytes = ((number of status bits) + 7) /
// 8" per point structure, and the Device Size of 8 is the byte count of the
// four 2-byte structures. For attribute 14 "The General Purpose I/O Device
// contains no warning status information": Device Size 0.
// The sizes are read from the value, so a device reporting, say, 7 DIPs or a
// longer common detail decodes as it reports itself.
Result<SupervisorDetail> decode_supervisor_detail(Bytes value) noexcept {
  ByteReader r{value};
  SupervisorDetail d;
  if (!read_sized_block(r, d.common)) return Errc::kTruncated;

  d.device_size = r.u8();
  const Bytes device = r.bytes(d.device_size);
  if (!r.ok()) return Errc::kTruncated;
  ByteReader dr{device};
  while (d.point_count < d.points.size() && !dr.at_end()) {
    PointStatus& p = d.points[d.point_count];
    p.count = dr.u8();
    const Bytes bits = dr.bytes((std::size_t{p.count} + 7) / 8);
    // The outer size held, the inner one did not: the sizes disagree.
    if (!dr.ok()) return Errc::kMalformed;
    for (std::size_t i = 0; i < bits.size(); ++i) p.bits[i] = bits[i];
    ++d.point_count;
  }
  d.device_extra.assign(dr.rest());  // at most 255 bytes: fits

  if (!read_sized_block(r, d.manufacturer)) return Errc::kTruncated;
  if (!r.at_end()) return Errc::kMalformed;
  return d;
}

}  // namespace dnbridge::profiles::cdn127
