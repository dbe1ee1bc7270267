#pragma once
// CIP service codes used on DeviceNet. Bit 7 of the service byte is the
// request/response flag; a success response carries service | 0x80.
#include <cstdint>
#include <string_view>

namespace dnbridge::cip {

enum class Service : std::uint8_t {
  kGetAttributesAll = 0x01,
  kSetAttributesAll = 0x02,
  kReset = 0x05,
  kCreate = 0x08,
  kDelete = 0x09,
  kApplyAttributes = 0x0D,
  kGetAttributeSingle = 0x0E,
  kSetAttributeSingle = 0x10,
  kErrorResponse = 0x14,  // sent as 0x94
  kAllocateMasterSlave = 0x4B,
  kReleaseMasterSlave = 0x4C,
};

inline constexpr std::uint8_t kResponseFlag = 0x80;
inline constexpr std::uint8_t kServiceMask = 0x7F;

// The service byte of a request.
constexpr std::uint8_t code(Service s) noexcept { return static_cast<std::uint8_t>(s); }

std::string_view to_string(Service service) noexcept;

// Services whose request body begins with an attribute number.
constexpr bool has_attribute(Service s) noexcept {
  return s == Service::kGetAttributeSingle || s == Service::kSetAttributeSingle;
}

}  // namespace dnbridge::cip
