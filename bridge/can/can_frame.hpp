#pragma once
// A classic CAN 2.0A data frame as DeviceNet uses it: 11-bit identifier, 0..8
// data bytes, no RTR, no extended identifiers. Transport-neutral: SocketCAN,
// the simulated bus and captures all convert to and from this type.
#include <algorithm>
#include <array>
#include <cstdint>
#include <initializer_list>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"

namespace dnbridge::can {

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;
inline constexpr std::size_t kMaxDataLength = 8;

struct CanFrame {
  std::uint32_t id = 0;
  std::uint8_t len = 0;
  std::array<std::uint8_t, kMaxDataLength> data{};

  Bytes payload() const noexcept { return Bytes(data.data(), len); }

  // Builds a frame, refusing identifiers over 11 bits and payloads over 8 bytes.
  static Result<CanFrame> make(std::uint32_t id, Bytes payload) noexcept {
    if (id > kMaxStandardId) return Errc::kInvalidIdentifier;
    if (payload.size() > kMaxDataLength) return Errc::kOutOfRange;
    CanFrame f;
    f.id = id;
    f.len = static_cast<std::uint8_t>(payload.size());
    std::copy(payload.begin(), payload.end(), f.data.begin());
    return f;
  }
  static Result<CanFrame> make(std::uint32_t id,
                               std::initializer_list<std::uint8_t> payload) noexcept {
    return make(id, Bytes(payload.begin(), payload.size()));
  }

  friend bool operator==(const CanFrame& a, const CanFrame& b) noexcept {
    return a.id == b.id && a.len == b.len &&
           std::equal(a.data.begin(), a.data.begin() + a.len, b.data.begin());
  }
};

}  // namespace dnbridge::can
