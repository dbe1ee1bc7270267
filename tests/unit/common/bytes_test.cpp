#include "bridge/common/bytes.hpp"

#include <gtest/gtest.h>

#include "bridge/common/result.hpp"

namespace dnbridge {
namespace {

TEST(ByteReader, ReadsLittleEndianAndTracksConsumption) {
  const std::uint8_t data[] = {0x01, 0x34, 0x12, 0x78, 0x56, 0x34, 0x12};
  ByteReader r{Bytes(data)};
  EXPECT_EQ(r.u8(), 0x01);
  EXPECT_EQ(r.u16le(), 0x1234);
  EXPECT_EQ(r.u32le(), 0x12345678u);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.at_end());
  EXPECT_EQ(r.consumed(), 7u);
}

TEST(ByteReader, FailsSafeAtTheEnd) {
  const std::uint8_t data[] = {0xAA};
  ByteReader r{Bytes(data)};
  EXPECT_EQ(r.u16le(), 0);  // does not fit: nothing read
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.consumed(), 0u);
  EXPECT_EQ(r.u8(), 0);  // stays failed
  EXPECT_TRUE(r.bytes(1).empty());
}

TEST(ByteWriter, RefusesToOverflow) {
  std::uint8_t out[3] = {};
  ByteWriter w{MutableBytes(out)};
  w.u16le(0xBEEF);
  EXPECT_TRUE(w.ok());
  w.u16le(0x1234);
  EXPECT_FALSE(w.ok());
  EXPECT_EQ(w.size(), 2u);
  EXPECT_EQ(out[0], 0xEF);
  EXPECT_EQ(out[1], 0xBE);
  EXPECT_EQ(out[2], 0x00);
}

TEST(InlineBytesTest, AppendRespectsCapacity) {
  InlineBytes<4> b;
  const std::uint8_t three[] = {1, 2, 3};
  EXPECT_TRUE(b.append(Bytes(three)));
  EXPECT_FALSE(b.append(Bytes(three)));
  EXPECT_EQ(b.size(), 3u);
}

TEST(ResultTest, CarriesValueOrError) {
  Result<int> good = 5;
  EXPECT_TRUE(good.ok());
  EXPECT_EQ(*good, 5);
  Result<int> bad = Errc::kTruncated;
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.error(), Errc::kTruncated);
  EXPECT_EQ(bad.value_or(7), 7);
  EXPECT_EQ(bad.error().message(), "input truncated");
}

}  // namespace
}  // namespace dnbridge
