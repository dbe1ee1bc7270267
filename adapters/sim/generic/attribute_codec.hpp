#pragma once
// Attribute values as a simulated device's object handlers write and read
// them: the response data of a Get, the request data of a Set, whose size
// must be exactly the attribute's (0x13 not enough data, 0x15 too much).
#include <cstddef>
#include <cstdint>

#include "adapters/sim/generic/connection_set.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::sim {

inline Reply put_u8(ByteWriter& w, std::uint8_t v) noexcept {
  w.u8(v);
  return kReplyOk;
}
inline Reply put_u16(ByteWriter& w, std::uint16_t v) noexcept {
  w.u16le(v);
  return kReplyOk;
}

inline Reply expect_size(Bytes data, std::size_t n) noexcept {
  if (data.size() < n) return reply_error(cip::GeneralStatus::kNotEnoughData);
  if (data.size() > n) return reply_error(cip::GeneralStatus::kTooMuchData);
  return kReplyOk;
}
inline Reply read_u8(Bytes data, std::uint8_t& v) noexcept {
  Reply r = expect_size(data, 1);
  if (r.ok()) v = data[0];
  return r;
}
inline Reply read_u16(Bytes data, std::uint16_t& v) noexcept {
  Reply r = expect_size(data, 2);
  if (r.ok()) v = static_cast<std::uint16_t>(data[0] | (data[1] << 8));
  return r;
}
// BOOL/BOOLEAN: 0 or 1.
inline Reply read_bool(Bytes data, bool& v) noexcept {
  std::uint8_t b = 0;
  Reply r = read_u8(data, b);
  if (!r.ok()) return r;
  if (b > 1) return reply_error(cip::GeneralStatus::kInvalidAttributeValue);
  v = b != 0;
  return kReplyOk;
}

// The response message to a request of `service` (service byte first) in
// `out`: success with what `w` holds, or the error `r` (0x11 when the data
// did not fit); its size.
inline std::size_t encode_reply(std::uint8_t service, Reply r, const ByteWriter& w,
                                MutableBytes out) noexcept {
  if (r.ok() && !w.ok()) r = reply_error(cip::GeneralStatus::kReplyDataTooLarge);
  if (r.ok()) {
    auto n = devicenet::encode_success_response(service, w.written(), out);
    if (n.ok()) return *n;
    r = reply_error(cip::GeneralStatus::kReplyDataTooLarge);
  }
  auto n = devicenet::encode_error_response(r.status, r.additional, out);
  return n.ok() ? *n : 0;
}

}  // namespace dnbridge::sim
