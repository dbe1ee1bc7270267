#pragma once
// What the parts of Node (node.cpp, node_lifecycle.cpp, node_identify.cpp,
// node_connections.cpp, node_poll.cpp) and its connections share: the
// DeviceNet objects the life cycle addresses, and text helpers.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "bridge/cip/general_status.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/explicit_client.hpp"

namespace dnbridge::devicenet::node_detail {

// Life-cycle reads that time out are retried this many times before the node
// is taken for gone: single lost frames must not cost a reconnection.
constexpr unsigned kStepTimeoutRetries = 2;

inline std::uint16_t to_ms(Duration d) {
  const auto ms = std::chrono::duration_cast<milliseconds>(d).count();
  return static_cast<std::uint16_t>(std::clamp<std::int64_t>(ms, 0, 0xFFFF));
}

// A UINT as the wire has it, little-endian.
inline std::array<std::uint8_t, 2> uint_le(std::uint16_t v) {
  return {static_cast<std::uint8_t>(v & 0xFF), static_cast<std::uint8_t>(v >> 8)};
}

inline std::optional<std::uint32_t> read_uint(Bytes data) {
  ByteReader r(data);
  if (data.size() == 1) return r.u8();
  if (data.size() == 2) return r.u16le();
  if (data.size() == 4) return r.u32le();
  return std::nullopt;
}

inline std::string status_text(const ExplicitResult& r) {
  if (r.error == Errc::kDeviceError) {
    auto name = cip::to_string(r.general_status);
    return fmt::format("{} (0x{:02X}/0x{:02X})", name.empty() ? "reserved status" : name,
                       static_cast<unsigned>(r.general_status), r.additional_status);
  }
  return r.error.message();
}

inline std::string hex(Bytes b) {
  std::string s;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ' ';
    s += fmt::format("{:02X}", b[i]);
  }
  return s.empty() ? "(empty)" : s;
}

}  // namespace dnbridge::devicenet::node_detail
