#include "bridge/cip/data_types.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string>

#include "support/bytes.hpp"

namespace dnbridge::cip {
namespace {

using test::ByteVec;
using test::hex;

TEST(ShortString, IdentityProductNameGolden) {
  // Identity attribute 7 of a CDN127: 06 length | 'C' 'D' 'N' '1' '2' '7'
  const ByteVec wire = {0x06, 'C', 'D', 'N', '1', '2', '7'};
  auto d = decode_short_string(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, "CDN127");
  EXPECT_EQ(static_cast<const void*>(d->data()), static_cast<const void*>(wire.data() + 1));

  std::array<std::uint8_t, 7> out{};
  ASSERT_EQ(short_string_size("CDN127"), 7u);
  auto n = encode_short_string("CDN127", out);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 7u);
  EXPECT_EQ(hex(out), hex(wire));
}

TEST(ShortString, TruncatedTrailingAndEmpty) {
  const ByteVec wire = {0x06, 'C', 'D', 'N', '1', '2', '7'};
  for (std::size_t n = 0; n < wire.size(); ++n) {
    EXPECT_EQ(decode_short_string(Bytes(wire.data(), n)).error(), Errc::kTruncated) << n;
  }
  ByteVec longer = wire;
  longer.push_back(0x00);
  EXPECT_EQ(decode_short_string(longer).error(), Errc::kMalformed);
  const ByteVec empty = {0x00};
  ASSERT_TRUE(decode_short_string(empty).ok());
  EXPECT_TRUE(decode_short_string(empty)->empty());
}

TEST(ShortString, EncodeLimits) {
  const std::string max(255, 'x'), over(256, 'x');
  std::array<std::uint8_t, 300> out{};
  auto n = encode_short_string(max, out);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 256u);
  EXPECT_EQ(out[0], 0xFF);
  EXPECT_EQ(encode_short_string(over, out).error(), Errc::kOutOfRange);
  for (std::size_t size = 0; size < 7; ++size) {
    EXPECT_EQ(encode_short_string("CDN127", MutableBytes(out.data(), size)).error(),
              Errc::kBufferTooSmall);
  }
}

TEST(String, UintLengthGolden) {
  // 06 00 length 6 LE | CDN127
  const ByteVec wire = {0x06, 0x00, 'C', 'D', 'N', '1', '2', '7'};
  auto d = decode_string(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, "CDN127");
  std::array<std::uint8_t, 8> out{};
  auto n = encode_string("CDN127", out);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(hex(out), hex(wire));
  for (std::size_t k = 0; k < wire.size(); ++k) {
    EXPECT_EQ(decode_string(Bytes(wire.data(), k)).error(), Errc::kTruncated) << k;
  }
  const std::string over(0x10000, 'x');
  std::vector<std::uint8_t> big(0x10010);
  EXPECT_EQ(encode_string(over, big).error(), Errc::kOutOfRange);
}

TEST(Readers, InsideAStructure) {
  // UINT 0x003B, SHORT_STRING "CDN127", STRING[3] "abc", USINT 9
  const ByteVec wire = {0x3B, 0x00, 0x06, 'C', 'D', 'N', '1', '2', '7', 'a', 'b', 'c', 0x09};
  ByteReader r(wire);
  EXPECT_EQ(r.u16le(), 59);
  EXPECT_EQ(read_short_string(r), "CDN127");
  EXPECT_EQ(read_fixed_string(r, 3), "abc");
  EXPECT_EQ(r.u8(), 9);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.at_end());

  const ByteVec cut = {0x06, 'C', 'D'};
  ByteReader c(cut);
  EXPECT_TRUE(read_short_string(c).empty());
  EXPECT_FALSE(c.ok());
  ByteReader f(cut);
  EXPECT_TRUE(read_fixed_string(f, 4).empty());
  EXPECT_FALSE(f.ok());
  EXPECT_EQ(f.consumed(), 0u);
}

TEST(TrimPadding, DropsTrailingNulsAndSpaces) {
  EXPECT_EQ(trim_padding("CDN127  "), "CDN127");
  EXPECT_EQ(trim_padding(std::string_view("CDN127\0\0", 8)), "CDN127");
  EXPECT_EQ(trim_padding(" A B "), " A B");
  EXPECT_EQ(trim_padding("   "), "");
  EXPECT_EQ(trim_padding(""), "");
}

TEST(ShortString, GarbageDecodesConsistentlyOrFails) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 10);
  for (int i = 0; i < 20000; ++i) {
    ByteVec in(length(rng));
    for (auto& b : in) b = static_cast<std::uint8_t>(byte(rng));
    if (!in.empty() && (i % 2) == 0) in[0] = static_cast<std::uint8_t>(in[0] % 10);
    auto d = decode_short_string(in);
    if (d.ok()) {
      ASSERT_EQ(d->size() + 1, in.size());
      EXPECT_EQ(d->size(), in[0]);
    }
    auto s = decode_string(in);
    if (s.ok()) {
      ASSERT_EQ(s->size() + 2, in.size());
    }
  }
}

TEST(ShortString, Iso8859_1CharactersBecomeUtf8) {
  EXPECT_EQ(utf8_from_iso8859_1("CDN127"), "CDN127");
  EXPECT_EQ(utf8_from_iso8859_1("\xB5s \xE4tz"), "\xC2\xB5s \xC3\xA4tz");
  EXPECT_EQ(utf8_from_iso8859_1("\x80\xFF"), "\xC2\x80\xC3\xBF");
  EXPECT_EQ(utf8_from_iso8859_1(""), "");
}

}  // namespace
}  // namespace dnbridge::cip
