#pragma once
#include <compare>
#include <cstdint>
#include <optional>

namespace dnbridge::devicenet {

// A DeviceNet node address, 0..63.
class MacId {
 public:
  static constexpr std::uint8_t kMax = 63;
  // 255 in the DeviceNet object's allocation information means "no master".
  static constexpr std::uint8_t kNone = 255;

  constexpr MacId() noexcept = default;
  static constexpr std::optional<MacId> from(unsigned v) noexcept {
    if (v > kMax) return std::nullopt;
    return MacId(static_cast<std::uint8_t>(v));
  }
  // For values already known to be valid (taken from a 6-bit field).
  static constexpr MacId from_bits(unsigned v) noexcept {
    return MacId(static_cast<std::uint8_t>(v & 0x3F));
  }

  constexpr std::uint8_t value() const noexcept { return v_; }
  // NOLINTNEXTLINE(modernize-use-nullptr): misread in a defaulted <=> (llvm-project#53961)
  friend constexpr auto operator<=>(MacId, MacId) noexcept = default;

 private:
  constexpr explicit MacId(std::uint8_t v) noexcept : v_(v) {}
  std::uint8_t v_ = 0;
};

}  // namespace dnbridge::devicenet
