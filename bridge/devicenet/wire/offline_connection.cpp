#include "bridge/devicenet/wire/offline_connection.hpp"

#include <array>

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

constexpr std::uint8_t kResponseBit = 0x80;
constexpr std::uint8_t kServiceMask = 0x7F;
constexpr std::uint8_t kMatchBit = 0x40;
constexpr std::uint8_t kValueMask = 0x3F;
constexpr std::uint8_t kPortMask = 0x7F;

std::uint8_t rr_service(bool response, std::uint8_t service) noexcept {
  return static_cast<std::uint8_t>((response ? kResponseBit : 0) | service);
}

}  // namespace

std::size_t comm_faulted_size(CommFaultedLayout layout) noexcept {
  switch (layout) {
    case CommFaultedLayout::kShort:
      return 2;
    case CommFaultedLayout::kShortWithDelay:
      return 3;
    case CommFaultedLayout::kPortVendorSerial:
      return 7;
    case CommFaultedLayout::kLong:
      return 8;
  }
  return 0;
}

Result<can::CanFrame> encode_comm_faulted(const CommFaultedMessage& m) noexcept {
  if (m.value > kValueMask || m.service > kServiceMask || m.physical_port > kPortMask) {
    return Errc::kOutOfRange;
  }
  std::array<std::uint8_t, 8> payload{};
  ByteWriter w{MutableBytes(payload)};
  const auto match_value = static_cast<std::uint8_t>((m.match ? kMatchBit : 0) | m.value);
  bool response = m.response;
  switch (m.layout) {
    case CommFaultedLayout::kShort:
      w.u8(match_value);
      w.u8(rr_service(m.response, m.service));
      break;
    case CommFaultedLayout::kShortWithDelay:
      w.u8(match_value);
      w.u8(rr_service(m.response, m.service));
      w.u8(m.delay_byte_offset);
      break;
    case CommFaultedLayout::kPortVendorSerial:
      response = true;
      w.u8(m.physical_port);
      w.u16le(m.vendor_id);
      w.u32le(m.serial_number);
      break;
    case CommFaultedLayout::kLong:
      w.u8(match_value);
      w.u8(rr_service(m.response, m.service));
      w.u16le(m.vendor_id);
      w.u32le(m.serial_number);
      break;
  }
  if (!w.ok()) return Errc::kBufferTooSmall;  // cannot happen: 8 bytes hold every layout
  const auto id = group4_id(response ? Group4Message::kCommFaultedResponse
                                     : Group4Message::kCommFaultedRequest);
  return can::CanFrame::make(id, w.written());
}

Result<CommFaultedMessage> decode_comm_faulted(Bytes payload) noexcept {
  CommFaultedMessage m;
  switch (payload.size()) {
    case 2:
      m.layout = CommFaultedLayout::kShort;
      break;
    case 3:
      m.layout = CommFaultedLayout::kShortWithDelay;
      break;
    case 7:
      m.layout = CommFaultedLayout::kPortVendorSerial;
      break;
    case 8:
      m.layout = CommFaultedLayout::kLong;
      break;
    default:
      return payload.size() > 8 ? Errc::kMalformed : Errc::kTruncated;
  }
  ByteReader r(payload);
  if (m.layout == CommFaultedLayout::kPortVendorSerial) {
    m.response = true;
    m.physical_port = r.u8() & kPortMask;
  } else {
    const std::uint8_t first = r.u8();
    m.match = (first & kMatchBit) != 0;
    m.value = first & kValueMask;
    const std::uint8_t second = r.u8();
    m.response = (second & kResponseBit) != 0;
    m.service = second & kServiceMask;
  }
  if (m.layout == CommFaultedLayout::kShortWithDelay) m.delay_byte_offset = r.u8();
  if (m.layout == CommFaultedLayout::kPortVendorSerial || m.layout == CommFaultedLayout::kLong) {
    m.vendor_id = r.u16le();
    m.serial_number = r.u32le();
  }
  // The length picked the layout, so the reads fit exactly; checked all the same.
  if (!r.ok() || !r.at_end()) return Errc::kMalformed;
  return m;
}

Result<can::CanFrame> encode_offline_ownership(const OfflineOwnershipMessage& m) noexcept {
  if (m.allocate > kServiceMask) return Errc::kOutOfRange;
  std::array<std::uint8_t, kOfflineOwnershipSize> payload{};
  ByteWriter w{MutableBytes(payload)};
  w.u8(m.client_mac.value());
  w.u8(rr_service(m.response, m.allocate));
  w.u16le(m.vendor_id);
  w.u32le(m.serial_number);
  const auto id = group4_id(m.response ? Group4Message::kOfflineOwnershipResponse
                                       : Group4Message::kOfflineOwnershipRequest);
  return can::CanFrame::make(id, w.written());
}

Result<OfflineOwnershipMessage> decode_offline_ownership(Bytes payload) noexcept {
  ByteReader r(payload);
  OfflineOwnershipMessage m;
  m.client_mac = MacId::from_bits(r.u8());
  const std::uint8_t second = r.u8();
  m.response = (second & kResponseBit) != 0;
  m.allocate = second & kServiceMask;
  m.vendor_id = r.u16le();
  m.serial_number = r.u32le();
  if (!r.ok()) return Errc::kTruncated;
  if (!r.at_end()) return Errc::kMalformed;
  return m;
}

}  // namespace dnbridge::devicenet
