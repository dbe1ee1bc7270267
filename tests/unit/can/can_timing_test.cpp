#include "bridge/can/can_timing.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string_view>

#include "support/bytes.hpp"

namespace dnbridge::can {
namespace {

using test::frame;

// Bits of a frame laid out as on the wire, for the arithmetic below:
//   SOF(1) ID(11) RTR IDE r0(3) DLC(4) DATA(8n) CRC(15) | CRCdel ACK ACKdel EOF(7) IFS(3)
// The first part (34 + 8n bits) is stuffed; the tail is 13 bits, fixed form.

TEST(CanTiming, Crc15MatchesCatalogueCheckValue) {
  // CRC-15/CAN in the CRC catalogue (poly 0x4599, init 0, no reflection, no
  // final xor): check value 0x059E over ASCII "123456789".
  constexpr std::string_view kCheck = "123456789";
  const std::array<std::uint8_t, 9> bytes{'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  ASSERT_EQ(kCheck.size(), bytes.size());
  EXPECT_EQ(crc15(Bytes(bytes)), 0x059E);
  EXPECT_EQ(crc15(Bytes()), 0);
}

TEST(CanTiming, AllZeroFrameWithoutData) {
  // ID 0x000, DLC 0: SOF..DLC are 19 dominant bits; the CRC of all zeros is 0,
  // so the stuffed region is 34 zeros. A stuff bit (1) follows zeros number 5,
  // 10, 15, 20, 25 and 30; each stuff bit is a run of one, the next zeros start
  // a new run. 34 zeros -> 6 stuff bits (the last 4 zeros stay short of 5).
  // Total: 34 + 6 + 13 = 53 bits; unstuffed 47, bound 55.
  const can::CanFrame f = frame(0x000, {});
  EXPECT_EQ(frame_crc(f), 0);
  EXPECT_EQ(stuff_bits(f), 6u);
  EXPECT_EQ(frame_bits(f), 53u);
  // 53 bit times: 2 us each at 500k, 4 us at 250k, 8 us at 125k.
  EXPECT_EQ(frame_duration(f, kBitrate500k), microseconds(106));
  EXPECT_EQ(frame_duration(f, kBitrate250k), microseconds(212));
  EXPECT_EQ(frame_duration(f, kBitrate125k), microseconds(424));
}

TEST(CanTiming, AllZeroFrameWithEightZeroBytes) {
  // ID 0x000, DLC 8, data 00 x 8. Unstuffed region (98 bits):
  //   15 zeros (SOF, ID, RTR, IDE, r0) | DLC 1000 | 64 zeros | CRC 0x145B
  // CRC 0x145B = 001 0100 0101 1011 (15 bits; independent bit-serial computation).
  // Stuffing:
  //   15 zeros                        -> stuff after zeros 5, 10, 15   = 3
  //   the stuff 1 and DLC's 1 form a run of two ones
  //   000 (DLC) + 64 data zeros + 00 (CRC start) = 69 zeros -> 13 stuff bits
  //     (after every 5th zero up to 65; 4 zeros then the CRC's 1)
  //   rest of CRC 101000101101 1: no run of five                    = 0
  // 16 stuff bits; 98 + 16 + 13 = 127 bits (unstuffed 111, bound 135).
  const can::CanFrame f = frame(0x000, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(frame_crc(f), 0x145B);
  EXPECT_EQ(stuff_bits(f), 16u);
  EXPECT_EQ(frame_bits(f), 127u);
  EXPECT_EQ(frame_duration(f, kBitrate500k), microseconds(254));
}

TEST(CanTiming, AllRecessiveIdentifierAndData) {
  // ID 0x7FF, DLC 8, data FF x 8. Unstuffed region:
  //   0 | 11111111111 | 000 | 1000 | 64 ones | CRC 0x4C89 = 100 1100 1000 1001
  // Stuffing:
  //   11 ID ones            -> stuff 0 after ones 5 and 10 (the 11th is a run of one) = 2
  //   11th ID one, 000 (RTR IDE r0), 1 000 (DLC) -> runs of 1, 3, 1, 3                = 0
  //   64 data ones          -> stuff after every 5th: 12, leaving a run of 4
  //   the CRC's first 1 makes it 5 -> one more                                          = 13
  //   rest of CRC 00110010001001: no run of five                                        = 0
  // 15 stuff bits; 98 + 15 + 13 = 126 bits.
  const can::CanFrame f = frame(0x7FF, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF});
  EXPECT_EQ(frame_crc(f), 0x4C89);
  EXPECT_EQ(stuff_bits(f), 15u);
  EXPECT_EQ(frame_bits(f), 126u);
}

TEST(CanTiming, FiveEqualBitsEndingTheCrcAreStuffed) {
  // ID 0x017, DLC 0. Unstuffed: 0 00000010111 000 0000 | CRC 0x521F = 101 0010 0001 1111
  //   SOF + 6 ID zeros = 7 zeros -> 1 stuff after the 5th
  //   1 0 111 then 7 zeros (RTR, IDE, r0, DLC) -> 1 stuff
  //   CRC 1 0 1 00 1 0000 11111: the last five ones -> 1 stuff before the CRC delimiter
  // 3 stuff bits; 34 + 3 + 13 = 50.
  const can::CanFrame f = frame(0x017, {});
  EXPECT_EQ(frame_crc(f), 0x521F);
  EXPECT_EQ(stuff_bits(f), 3u);
  EXPECT_EQ(frame_bits(f), 50u);
}

TEST(CanTiming, DeviceNetExplicitRequest) {
  // ID 0x41C (Group 2, MAC 3, explicit request), Get_Attribute_Single of
  // Identity (class 1) instance 1 attribute 7: 00 0E 01 01 07. CRC 0x051B; 7
  // stuff bits by the same procedure; 19 + 40 + 15 + 7 + 13 = 94 bits.
  const can::CanFrame f = frame(0x41C, {0x00, 0x0E, 0x01, 0x01, 0x07});
  EXPECT_EQ(frame_crc(f), 0x051B);
  EXPECT_EQ(frame_bits(f), 94u);
  EXPECT_EQ(frame_duration(f, kBitrate125k), microseconds(752));
}

TEST(CanTiming, BoundsMatchFactsSheet) {
  // bridge/PROTOCOL.md §10: 47 + 8n unstuffed, 55 + 10n worst case; at 500k the
  // worst case is 110 us (0 bytes) to 270 us (8 bytes), at 125k 440 to 1080 us.
  EXPECT_EQ(unstuffed_frame_bits(0), 47u);
  EXPECT_EQ(max_frame_bits(8), 135u);
  EXPECT_EQ(bits_duration(max_frame_bits(0), kBitrate500k), microseconds(110));
  EXPECT_EQ(bits_duration(max_frame_bits(8), kBitrate500k), microseconds(270));
  EXPECT_EQ(bits_duration(max_frame_bits(0), kBitrate125k), microseconds(440));
  EXPECT_EQ(bits_duration(max_frame_bits(8), kBitrate125k), microseconds(1080));
  EXPECT_EQ(bits_duration(1, kBitrate250k), microseconds(4));
  EXPECT_EQ(bits_duration(10, 0), Duration::zero());
}

TEST(CanTiming, EveryShortFrameWithinBounds) {
  // Exhaustive over identifiers for 0 and 1 data byte.
  std::uint32_t worst0 = 0;
  for (std::uint32_t id = 0; id <= can::kMaxStandardId; ++id) {
    const std::uint32_t bits = frame_bits(frame(id, {}));
    EXPECT_GE(bits, unstuffed_frame_bits(0));
    EXPECT_LE(bits, max_frame_bits(0));
    worst0 = std::max(worst0, bits);
    for (std::uint32_t b = 0; b < 256; ++b) {
      const std::uint32_t bits1 = frame_bits(frame(id, {static_cast<std::uint8_t>(b)}));
      ASSERT_GE(bits1, unstuffed_frame_bits(1)) << id << ' ' << b;
      ASSERT_LE(bits1, max_frame_bits(1)) << id << ' ' << b;
    }
  }
  // Stuffing does lengthen some frames well past the unstuffed 47.
  EXPECT_GT(worst0, 51u);
}

TEST(CanTiming, RandomFramesWithinBounds) {
  std::mt19937_64 rng(20070101);
  for (int i = 0; i < 20000; ++i) {
    can::CanFrame f;
    f.id = static_cast<std::uint32_t>(rng() & can::kMaxStandardId);
    f.len = static_cast<std::uint8_t>(rng() % 9);
    for (std::size_t k = 0; k < f.len; ++k) f.data[k] = static_cast<std::uint8_t>(rng());
    const std::uint32_t bits = frame_bits(f);
    ASSERT_GE(bits, unstuffed_frame_bits(f.len)) << test::hex(f);
    ASSERT_LE(bits, max_frame_bits(f.len)) << test::hex(f);
    ASSERT_EQ(bits, unstuffed_frame_bits(f.len) + stuff_bits(f));
  }
}

TEST(CanTiming, OversizedLengthCountsAsEightBytes) {
  // A raw CanFrame can carry len > 8; the wire cannot.
  can::CanFrame f = frame(0x123, {1, 2, 3, 4, 5, 6, 7, 8});
  const std::uint32_t eight = frame_bits(f);
  f.len = 15;
  EXPECT_EQ(frame_bits(f), eight);
}

}  // namespace
}  // namespace dnbridge::can
