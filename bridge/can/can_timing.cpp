#include "bridge/can/can_timing.hpp"

#include <algorithm>
#include <array>

namespace dnbridge::can {
namespace {

constexpr std::uint16_t kCrcPolynomial = 0x4599;
// SOF (1) + identifier (11) + RTR, IDE, r0 (3) + DLC (4) + 8 data bytes + CRC (15).
constexpr std::size_t kMaxStuffedRegion = 1 + 11 + 3 + 4 + 64 + 15;
// CRC delimiter, ACK slot, ACK delimiter, EOF (7), intermission (3): never stuffed.
constexpr std::uint32_t kTailBits = 1 + 1 + 1 + 7 + 3;

// CAN 2.0 specification, part A §3.1.1: shift one bit into the 15-bit register.
constexpr std::uint16_t crc_step(std::uint16_t crc, bool bit) noexcept {
  const bool feedback = bit != (((crc >> 14) & 1U) != 0);
  crc = static_cast<std::uint16_t>((crc << 1) & 0x7FFF);
  if (feedback) crc = static_cast<std::uint16_t>(crc ^ kCrcPolynomial);
  return crc;
}

// The bits from SOF to the end of the CRC, in transmission order (0 = dominant).
class BitString {
 public:
  void push(std::uint32_t value, int width) noexcept {
    for (int i = width - 1; i >= 0; --i) bits_[size_++] = ((value >> i) & 1U) != 0;
  }
  std::size_t size() const noexcept { return size_; }
  bool operator[](std::size_t i) const noexcept { return bits_[i]; }

 private:
  std::array<bool, kMaxStuffedRegion> bits_{};
  std::size_t size_ = 0;
};

std::uint8_t data_length(const CanFrame& frame) noexcept {
  return static_cast<std::uint8_t>(std::min<std::size_t>(frame.len, can::kMaxDataLength));
}

// SOF through the data field: what the CRC covers.
BitString crc_region(const CanFrame& frame) noexcept {
  BitString s;
  const std::uint8_t n = data_length(frame);
  s.push(0, 1);                                // SOF, dominant
  s.push(frame.id & can::kMaxStandardId, 11);  // identifier, MSB first
  s.push(0, 3);                                // RTR (data frame), IDE (standard), r0
  s.push(n, 4);                                // DLC
  for (std::size_t i = 0; i < n; ++i) s.push(frame.data[i], 8);
  return s;
}

std::uint16_t crc_of(const BitString& s) noexcept {
  std::uint16_t crc = 0;
  for (std::size_t i = 0; i < s.size(); ++i) crc = crc_step(crc, s[i]);
  return crc;
}

}  // namespace

std::uint16_t crc15(Bytes bytes) noexcept {
  std::uint16_t crc = 0;
  for (std::uint8_t b : bytes) {
    for (int i = 7; i >= 0; --i) crc = crc_step(crc, ((b >> i) & 1) != 0);
  }
  return crc;
}

std::uint16_t frame_crc(const CanFrame& frame) noexcept { return crc_of(crc_region(frame)); }

std::uint32_t stuff_bits(const CanFrame& frame) noexcept {
  BitString s = crc_region(frame);
  s.push(crc_of(s), 15);
  // After five equal bits the transmitter inserts their complement; that bit
  // starts the next run, so it can itself be the first of five.
  std::uint32_t inserted = 0;
  bool last = s[0];
  int run = 1;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (run == 5) {
      ++inserted;
      last = !last;
      run = 1;
    }
    if (s[i] == last) {
      ++run;
    } else {
      last = s[i];
      run = 1;
    }
  }
  // Five equal bits ending the CRC are followed by a stuff bit too, before the
  // CRC delimiter.
  if (run == 5) ++inserted;
  return inserted;
}

std::uint32_t frame_bits(const CanFrame& frame) noexcept {
  const std::uint32_t n = data_length(frame);
  return 1 + 11 + 3 + 4 + 8 * n + 15 + stuff_bits(frame) + kTailBits;
}

Duration bits_duration(std::uint64_t bits, std::uint32_t bitrate) noexcept {
  if (bitrate == 0) return Duration::zero();
  constexpr std::uint64_t kNanosPerSecond = 1'000'000'000;
  return Duration(static_cast<Duration::rep>((bits * kNanosPerSecond + bitrate - 1) / bitrate));
}

Duration frame_duration(const CanFrame& frame, std::uint32_t bitrate) noexcept {
  return bits_duration(frame_bits(frame), bitrate);
}

}  // namespace dnbridge::can
