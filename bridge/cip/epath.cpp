#include "bridge/cip/epath.hpp"

namespace dnbridge::cip {
namespace {

constexpr std::uint8_t kSegmentTypeMask = 0xE0;
constexpr std::uint8_t kLogicalTypeMask = 0x1C;
constexpr std::uint8_t kFormatMask = 0x03;

constexpr LogicalFormat format_for(std::uint32_t value, LogicalFormat min_format) noexcept {
  if (value <= 0xFF && min_format == LogicalFormat::k8Bit) return LogicalFormat::k8Bit;
  if (value <= 0xFFFF && min_format != LogicalFormat::k32Bit) return LogicalFormat::k16Bit;
  return LogicalFormat::k32Bit;
}

constexpr std::size_t value_size(LogicalFormat format) noexcept {
  switch (format) {
    case LogicalFormat::k8Bit:
      return 1;
    case LogicalFormat::k16Bit:
      return 2;
    case LogicalFormat::k32Bit:
      return 4;
  }
  return 0;
}

std::size_t segment_size(const std::optional<std::uint32_t>& value,
                         LogicalFormat min_format) noexcept {
  return value ? 1 + value_size(format_for(*value, min_format)) : 0;
}

void write_segment(ByteWriter& w, LogicalType type, const std::optional<std::uint32_t>& value,
                   LogicalFormat min_format) noexcept {
  if (!value) return;
  const LogicalFormat format = format_for(*value, min_format);
  w.u8(logical_segment_byte(type, format));
  switch (format) {
    case LogicalFormat::k8Bit:
      w.u8(static_cast<std::uint8_t>(*value));
      break;
    case LogicalFormat::k16Bit:
      w.u16le(static_cast<std::uint16_t>(*value));
      break;
    case LogicalFormat::k32Bit:
      w.u32le(*value);
      break;
  }
}

// Position of each segment type in the accepted order; -1 for types not handled.
constexpr int order_of(LogicalType type) noexcept {
  switch (type) {
    case LogicalType::kClass:
      return 0;
    case LogicalType::kInstance:
      return 1;
    case LogicalType::kConnectionPoint:
      return 2;
    case LogicalType::kAttribute:
      return 3;
    case LogicalType::kMember:
      return -1;
  }
  return -1;
}

}  // namespace

std::size_t encoded_size(const EPath& path, LogicalFormat min_format) noexcept {
  return segment_size(path.class_id, min_format) + segment_size(path.instance_id, min_format) +
         segment_size(path.connection_point, min_format) +
         segment_size(path.attribute, LogicalFormat::k8Bit);
}

Result<std::size_t> encode(const EPath& path, MutableBytes out, LogicalFormat min_format) noexcept {
  if (out.size() < encoded_size(path, min_format)) return Errc::kBufferTooSmall;
  ByteWriter w(out);
  write_segment(w, LogicalType::kClass, path.class_id, min_format);
  write_segment(w, LogicalType::kInstance, path.instance_id, min_format);
  write_segment(w, LogicalType::kConnectionPoint, path.connection_point, min_format);
  write_segment(w, LogicalType::kAttribute, path.attribute, LogicalFormat::k8Bit);
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

std::vector<std::uint8_t> encoded(const EPath& path) {
  std::vector<std::uint8_t> out(encoded_size(path));
  auto n = encode(path, MutableBytes(out));
  out.resize(n ? *n : 0);
  return out;
}

Result<EPath> decode_epath(Bytes data) noexcept {
  ByteReader r(data);
  EPath path;
  int last = -1;
  while (!r.at_end()) {
    const std::uint8_t segment = r.u8();
    if ((segment & kSegmentTypeMask) != kLogicalSegment) return Errc::kUnsupported;
    const std::uint8_t type_bits = static_cast<std::uint8_t>((segment & kLogicalTypeMask) >> 2);
    const std::uint8_t format_bits = segment & kFormatMask;
    if (type_bits > static_cast<std::uint8_t>(LogicalType::kAttribute)) {
      return Errc::kUnsupported;  // electronic key, service ID, reserved
    }
    if (format_bits > static_cast<std::uint8_t>(LogicalFormat::k32Bit)) return Errc::kMalformed;
    const auto type = static_cast<LogicalType>(type_bits);
    const int order = order_of(type);
    if (order < 0) return Errc::kUnsupported;
    if (order <= last) return Errc::kMalformed;
    last = order;
    std::uint32_t value = 0;
    switch (static_cast<LogicalFormat>(format_bits)) {
      case LogicalFormat::k8Bit:
        value = r.u8();
        break;
      case LogicalFormat::k16Bit:
        value = r.u16le();
        break;
      case LogicalFormat::k32Bit:
        value = r.u32le();
        break;
    }
    if (!r.ok()) return Errc::kTruncated;
    switch (type) {
      case LogicalType::kClass:
        path.class_id = value;
        break;
      case LogicalType::kInstance:
        path.instance_id = value;
        break;
      case LogicalType::kConnectionPoint:
        path.connection_point = value;
        break;
      case LogicalType::kAttribute:
        path.attribute = value;
        break;
      case LogicalType::kMember:
        return Errc::kUnsupported;
    }
  }
  return path;
}

}  // namespace dnbridge::cip
