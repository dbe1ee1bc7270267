#pragma once
// CIP EPATH of logical segments, in the packed form DeviceNet uses
// (bridge/PROTOCOL.md §8): each segment is a segment byte
//   0x20 | (logical type << 2) | format
// followed by the value, 1, 2 or 4 bytes little-endian, with no pad byte.
//   20 04 24 01 30 03           class 4, instance 1, attribute 3
//   21 04 00 25 01 00 30 03     the same with 16-bit class and instance
// Connection paths (Connection object attributes 14/16) and Assembly member
// paths use this form; an empty path is valid (e.g. Assembly padding members).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::cip {

enum class LogicalType : std::uint8_t {
  kClass = 0,
  kInstance = 1,
  kMember = 2,
  kConnectionPoint = 3,
  kAttribute = 4,
};

enum class LogicalFormat : std::uint8_t { k8Bit = 0, k16Bit = 1, k32Bit = 2 };

inline constexpr std::uint8_t kLogicalSegment = 0x20;  // segment type 1 in bits 7..5

constexpr std::uint8_t logical_segment_byte(LogicalType type, LogicalFormat format) noexcept {
  return static_cast<std::uint8_t>(kLogicalSegment | (static_cast<std::uint8_t>(type) << 2) |
                                   static_cast<std::uint8_t>(format));
}

// A path to a class, an instance, and an attribute or connection point. Every
// part is optional; encoded in the order class, instance, connection point,
// attribute, each with the smallest format that holds its value (or
// `min_format`, see encode()). Decoding accepts any format for any value.
struct EPath {
  std::optional<std::uint32_t> class_id{};
  std::optional<std::uint32_t> instance_id{};
  std::optional<std::uint32_t> connection_point{};
  std::optional<std::uint32_t> attribute{};

  bool empty() const noexcept {
    return !class_id && !instance_id && !connection_point && !attribute;
  }
  friend bool operator==(const EPath&, const EPath&) = default;
};

// Bytes the path takes when encoded. `min_format` widens the class, instance
// and connection point segments of small values (for devices that expect the
// 16-bit form, `21 04 00 25 01 00 30 03`); the attribute segment keeps its
// smallest format, and a value never narrows.
std::size_t encoded_size(const EPath& path,
                         LogicalFormat min_format = LogicalFormat::k8Bit) noexcept;
// Encodes into `out`; kBufferTooSmall if it does not fit. Returns the size written.
Result<std::size_t> encode(const EPath& path, MutableBytes out,
                           LogicalFormat min_format = LogicalFormat::k8Bit) noexcept;
// The path's bytes (each segment in its smallest format).
std::vector<std::uint8_t> encoded(const EPath& path);
// Decodes a whole path (its length is known from the attribute or field that
// holds it). Fails with kTruncated when a segment's value is cut off, kMalformed
// for a reserved format, a repeated segment or segments out of the order above,
// kUnsupported for any other segment (member, electronic key, port, data...).
Result<EPath> decode_epath(Bytes data) noexcept;

}  // namespace dnbridge::cip
