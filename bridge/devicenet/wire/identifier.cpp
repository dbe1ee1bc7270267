#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {

Result<Identifier> decode_identifier(std::uint32_t can_id) noexcept {
  if (can_id > 0x7EF) return Errc::kInvalidIdentifier;  // 0x7F0-0x7FF invalid, >11 bits too
  Identifier id;
  if ((can_id & 0x400) == 0) {
    id.group = MessageGroup::k1;
    id.message_id = static_cast<std::uint8_t>((can_id >> 6) & 0x0F);
    id.mac = MacId::from_bits(can_id);
  } else if ((can_id & 0x600) == 0x400) {
    id.group = MessageGroup::k2;
    id.mac = MacId::from_bits(can_id >> 3);
    id.message_id = static_cast<std::uint8_t>(can_id & 0x07);
  } else if (can_id < 0x7C0) {
    id.group = MessageGroup::k3;
    id.message_id = static_cast<std::uint8_t>((can_id >> 6) & 0x07);
    id.mac = MacId::from_bits(can_id);
  } else {
    id.group = MessageGroup::k4;
    id.message_id = static_cast<std::uint8_t>(can_id & 0x3F);
  }
  return id;
}

Result<std::uint32_t> encode_identifier(const Identifier& id) noexcept {
  const std::uint32_t mac = id.mac.value();
  switch (id.group) {
    case MessageGroup::k1:
      if (id.message_id > 0x0F) return Errc::kOutOfRange;
      return (static_cast<std::uint32_t>(id.message_id) << 6) | mac;
    case MessageGroup::k2:
      if (id.message_id > 0x07) return Errc::kOutOfRange;
      return 0x400u | (mac << 3) | id.message_id;
    case MessageGroup::k3:
      if (id.message_id > 0x06) return Errc::kOutOfRange;  // 7 would fall into Group 4
      return 0x600u | (static_cast<std::uint32_t>(id.message_id) << 6) | mac;
    case MessageGroup::k4:
      if (id.message_id > 0x2F) return Errc::kOutOfRange;
      return 0x7C0u | id.message_id;
  }
  return Errc::kOutOfRange;
}

}  // namespace dnbridge::devicenet
