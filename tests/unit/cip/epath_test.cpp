#include "bridge/cip/epath.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "support/bytes.hpp"

namespace dnbridge::cip {
namespace {

using test::ByteVec;
using test::hex;

ByteVec encode_vec(const EPath& p, LogicalFormat min = LogicalFormat::k8Bit) {
  ByteVec out(encoded_size(p, min));
  auto n = encode(p, out, min);
  EXPECT_TRUE(n.ok());
  if (n.ok()) {
    EXPECT_EQ(*n, out.size());
  }
  return out;
}

TEST(EPath, SegmentBytes) {
  EXPECT_EQ(logical_segment_byte(LogicalType::kClass, LogicalFormat::k8Bit), 0x20);
  EXPECT_EQ(logical_segment_byte(LogicalType::kClass, LogicalFormat::k16Bit), 0x21);
  EXPECT_EQ(logical_segment_byte(LogicalType::kInstance, LogicalFormat::k8Bit), 0x24);
  EXPECT_EQ(logical_segment_byte(LogicalType::kInstance, LogicalFormat::k32Bit), 0x26);
  EXPECT_EQ(logical_segment_byte(LogicalType::kMember, LogicalFormat::k8Bit), 0x28);
  EXPECT_EQ(logical_segment_byte(LogicalType::kConnectionPoint, LogicalFormat::k8Bit), 0x2C);
  EXPECT_EQ(logical_segment_byte(LogicalType::kAttribute, LogicalFormat::k8Bit), 0x30);
}

TEST(EPath, AssemblyAttributePathGolden8Bit) {
  const EPath p{.class_id = 4, .instance_id = 1, .attribute = 3};
  // 20 04 class 4 (Assembly) | 24 01 instance 1 | 30 03 attribute 3 (data)
  EXPECT_EQ(hex(encode_vec(p)), "20 04 24 01 30 03");
  const ByteVec wire = {0x20, 0x04, 0x24, 0x01, 0x30, 0x03};
  auto d = decode_epath(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, p);
}

TEST(EPath, SixteenBitPackedFormGolden) {
  const EPath p{.class_id = 4, .instance_id = 0x0102, .attribute = 3};
  // 21 04 00 class 4, 16-bit LE, no pad | 25 02 01 instance 0x0102 | 30 03 attribute 3
  EXPECT_EQ(hex(encode_vec(p)), "20 04 25 02 01 30 03");  // class stays 8-bit by default
  EXPECT_EQ(hex(encode_vec(p, LogicalFormat::k16Bit)), "21 04 00 25 02 01 30 03");
  const EPath small{.class_id = 4, .instance_id = 1, .attribute = 3};
  EXPECT_EQ(hex(encode_vec(small, LogicalFormat::k16Bit)), "21 04 00 25 01 00 30 03");
  const ByteVec wire = {0x21, 0x04, 0x00, 0x25, 0x01, 0x00, 0x30, 0x03};
  auto d = decode_epath(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, small);  // the value, whatever the format on the wire
}

TEST(EPath, ThirtyTwoBitAndConnectionPoint) {
  const EPath wide{.instance_id = 0x12345678};
  EXPECT_EQ(hex(encode_vec(wide)), "26 78 56 34 12");
  const EPath cp{.class_id = 4, .connection_point = 0x65};
  // 20 04 class Assembly | 2C 65 connection point 0x65
  EXPECT_EQ(hex(encode_vec(cp)), "20 04 2C 65");
  for (const EPath& p : {wide, cp}) {
    auto d = decode_epath(encode_vec(p));
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(*d, p);
  }
}

TEST(EPath, EmptyPath) {
  const EPath empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(encoded_size(empty), 0u);
  EXPECT_EQ(encode(empty, MutableBytes()).value(), 0u);
  auto d = decode_epath(Bytes());
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d->empty());
}

TEST(EPath, EveryPrefixIsAPathOrTruncated) {
  const ByteVec wire = {0x21, 0x04, 0x00, 0x25, 0x01, 0x00, 0x30, 0x03};
  for (std::size_t n = 0; n <= wire.size(); ++n) {
    auto d = decode_epath(Bytes(wire.data(), n));
    const bool boundary = n == 0 || n == 3 || n == 6 || n == 8;
    EXPECT_EQ(d.ok(), boundary) << n;
    if (!boundary) {
      EXPECT_EQ(d.error(), Errc::kTruncated) << n;
    }
  }
  EXPECT_EQ(decode_epath(Bytes(wire.data(), 3))->class_id, 4u);
  EXPECT_FALSE(decode_epath(Bytes(wire.data(), 3))->instance_id.has_value());
}

TEST(EPath, RejectsUnknownReservedAndDisorderedSegments) {
  const ByteVec reserved_format = {0x23, 0x04};         // format 3
  const ByteVec member = {0x20, 0x04, 0x28, 0x01};      // member segment
  const ByteVec key = {0x34, 0x04};                     // electronic key
  const ByteVec port = {0x01, 0x02};                    // port segment
  const ByteVec data = {0x80, 0x00};                    // data segment
  const ByteVec repeated = {0x20, 0x04, 0x20, 0x05};    // two classes
  const ByteVec disordered = {0x24, 0x01, 0x20, 0x04};  // instance before class
  EXPECT_EQ(decode_epath(reserved_format).error(), Errc::kMalformed);
  EXPECT_EQ(decode_epath(member).error(), Errc::kUnsupported);
  EXPECT_EQ(decode_epath(key).error(), Errc::kUnsupported);
  EXPECT_EQ(decode_epath(port).error(), Errc::kUnsupported);
  EXPECT_EQ(decode_epath(data).error(), Errc::kUnsupported);
  EXPECT_EQ(decode_epath(repeated).error(), Errc::kMalformed);
  EXPECT_EQ(decode_epath(disordered).error(), Errc::kMalformed);
}

TEST(EPath, EncodeRefusesSmallBuffers) {
  const EPath p{.class_id = 4, .instance_id = 0x1234, .attribute = 3};
  const std::size_t size = encoded_size(p);
  ASSERT_EQ(size, 7u);
  std::array<std::uint8_t, 8> out{};
  for (std::size_t n = 0; n < size; ++n) {
    EXPECT_EQ(encode(p, MutableBytes(out.data(), n)).error(), Errc::kBufferTooSmall) << n;
  }
}

TEST(EPath, GarbageDecodesConsistentlyOrFails) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 12);
  int decoded = 0;
  for (int i = 0; i < 20000; ++i) {
    ByteVec in(length(rng));
    for (auto& b : in) {
      b = static_cast<std::uint8_t>(byte(rng));
      if ((i % 2) == 0) b = static_cast<std::uint8_t>(0x20 | (b & 0x13));  // mostly logical
    }
    auto d = decode_epath(in);
    if (!d.ok()) continue;
    ++decoded;
    auto again = decode_epath(encode_vec(*d));
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(*again, *d);
    EXPECT_LE(encoded_size(*d), in.size());
  }
  EXPECT_GT(decoded, 100);  // the loop did exercise successful decodes
}

}  // namespace
}  // namespace dnbridge::cip
