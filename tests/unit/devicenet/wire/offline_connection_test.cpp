#include "bridge/devicenet/wire/offline_connection.hpp"

#include <gtest/gtest.h>

#include <random>

#include "support/bytes.hpp"

namespace dnbridge::devicenet {
namespace {

using test::ByteVec;
using test::hex;

Bytes view(const ByteVec& v) { return Bytes(v.data(), v.size()); }

// --- Communication Faulted: golden frames, field by field -------------------

TEST(CommFaulted, ShortRequestGolden) {
  const CommFaultedMessage m{.layout = CommFaultedLayout::kShort,
                             .response = false,
                             .match = true,
                             .value = 3,
                             .service = kCommFaultedIdentifyService};
  auto f = encode_comm_faulted(m);
  ASSERT_TRUE(f.ok());
  // ID 0x7ED request | 43: rsv 0, match 1, value 3 | 4B: R/R 0, service 0x4B
  EXPECT_EQ(hex(*f), "7ED: 43 4B");
  auto d = decode_comm_faulted(f->payload());
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, m);
}

TEST(CommFaulted, ShortWithDelayMatchesTheVendorManualExample) {
  // ICP DAS I-7242D example: "3F 4B 02" = match 0, value 0x3F, service 0x4B,
  // time delay byte offset 2.
  const ByteVec wire{0x3F, 0x4B, 0x02};
  auto d = decode_comm_faulted(view(wire));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->layout, CommFaultedLayout::kShortWithDelay);
  EXPECT_FALSE(d->response);
  EXPECT_FALSE(d->match);
  EXPECT_EQ(d->value, 0x3F);
  EXPECT_EQ(d->service, 0x4B);
  EXPECT_EQ(d->delay_byte_offset, 2);
  auto f = encode_comm_faulted(*d);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(hex(*f), "7ED: 3F 4B 02");
}

TEST(CommFaulted, LongResponseGolden) {
  const CommFaultedMessage m{.layout = CommFaultedLayout::kLong,
                             .response = true,
                             .match = false,
                             .value = 3,
                             .service = kCommFaultedIdentifyService,
                             .vendor_id = 0x0123,
                             .serial_number = 0x89ABCDEF};
  auto f = encode_comm_faulted(m);
  ASSERT_TRUE(f.ok());
  // ID 0x7EC response | 03: rsv 0, match 0, value 3 | CB: R/R 1, service 0x4B |
  // 23 01 vendor 0x0123 LE | EF CD AB 89 serial 0x89ABCDEF LE
  EXPECT_EQ(hex(*f), "7EC: 03 CB 23 01 EF CD AB 89");
  auto d = decode_comm_faulted(f->payload());
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, m);
}

TEST(CommFaulted, PortVendorSerialMatchesTheVendorManualExample) {
  // ICP DAS I-7242D example response "00 23 03 01 00 00 00": port 0,
  // vendor 0x0323, serial 1.
  const ByteVec wire{0x00, 0x23, 0x03, 0x01, 0x00, 0x00, 0x00};
  auto d = decode_comm_faulted(view(wire));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->layout, CommFaultedLayout::kPortVendorSerial);
  EXPECT_TRUE(d->response);
  EXPECT_EQ(d->physical_port, 0);
  EXPECT_EQ(d->vendor_id, 0x0323);
  EXPECT_EQ(d->serial_number, 1u);
  // Always a response, whatever the flag says.
  CommFaultedMessage m = *d;
  m.response = false;
  auto f = encode_comm_faulted(m);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(hex(*f), "7EC: 00 23 03 01 00 00 00");
}

TEST(CommFaulted, FieldsOutsideTheLayoutAreNotEncoded) {
  const CommFaultedMessage m{.layout = CommFaultedLayout::kShort,
                             .value = 1,
                             .service = 0x10,
                             .delay_byte_offset = 9,
                             .physical_port = 5,
                             .vendor_id = 0xFFFF,
                             .serial_number = 0xFFFFFFFF};
  auto f = encode_comm_faulted(m);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(hex(*f), "7ED: 01 10");
  auto d = decode_comm_faulted(f->payload());
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->vendor_id, 0);
  EXPECT_EQ(d->serial_number, 0u);
  EXPECT_EQ(d->delay_byte_offset, 0);
}

TEST(CommFaulted, ReservedBitIsIgnoredOnDecode) {
  const ByteVec wire{0xC5, 0x4B};  // rsv 1, match 1, value 5
  auto d = decode_comm_faulted(view(wire));
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d->match);
  EXPECT_EQ(d->value, 5);
  EXPECT_EQ(hex(encode_comm_faulted(*d)->payload()), "45 4B");
}

TEST(CommFaulted, OutOfRangeFieldsAreRefused) {
  EXPECT_EQ(encode_comm_faulted({.value = 64}).error(), Errc::kOutOfRange);
  EXPECT_EQ(encode_comm_faulted({.service = 0x80}).error(), Errc::kOutOfRange);
  EXPECT_EQ(
      encode_comm_faulted({.layout = CommFaultedLayout::kPortVendorSerial, .physical_port = 0x80})
          .error(),
      Errc::kOutOfRange);
}

TEST(CommFaulted, LengthsWithoutALayoutFail) {
  const ByteVec full{0x03, 0xCB, 0x23, 0x01, 0xEF, 0xCD, 0xAB, 0x89, 0x00};
  for (std::size_t n : {0u, 1u, 4u, 5u, 6u}) {
    EXPECT_EQ(decode_comm_faulted(Bytes(full.data(), n)).error(), Errc::kTruncated) << n;
  }
  EXPECT_EQ(decode_comm_faulted(view(full)).error(), Errc::kMalformed);
}

TEST(CommFaulted, SizesOfTheLayouts) {
  EXPECT_EQ(comm_faulted_size(CommFaultedLayout::kShort), 2u);
  EXPECT_EQ(comm_faulted_size(CommFaultedLayout::kShortWithDelay), 3u);
  EXPECT_EQ(comm_faulted_size(CommFaultedLayout::kPortVendorSerial), 7u);
  EXPECT_EQ(comm_faulted_size(CommFaultedLayout::kLong), 8u);
}

// Random bytes: every length decodes or fails cleanly, and what decodes encodes
// back to the same bytes (reserved bits aside) at the size of its layout.
TEST(CommFaulted, GarbageDecodesOrFailsAndRoundTrips) {
  std::mt19937 rng(7);
  for (int i = 0; i < 2000; ++i) {
    ByteVec b(static_cast<std::size_t>(rng() % 12));
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    auto d = decode_comm_faulted(view(b));
    if (!d.ok()) {
      EXPECT_TRUE(d.error() == Errc::kTruncated || d.error() == Errc::kMalformed);
      continue;
    }
    EXPECT_EQ(comm_faulted_size(d->layout), b.size());
    auto f = encode_comm_faulted(*d);
    ASSERT_TRUE(f.ok());
    ASSERT_EQ(f->len, b.size());
    ByteVec expected = b;
    expected[0] &= 0x7F;  // the reserved bit, or the port's unused top bit
    EXPECT_EQ(ByteVec(f->data.begin(), f->data.begin() + f->len), expected);
    EXPECT_EQ(f->id, d->response ? 0x7ECu : 0x7EDu);
  }
}

// --- Offline Ownership ---------------------------------------------------------

TEST(OfflineOwnership, RequestGolden) {
  const OfflineOwnershipMessage m{.response = false,
                                  .client_mac = MacId::from_bits(10),
                                  .allocate = kOfflineAllocate,
                                  .vendor_id = 0x0123,
                                  .serial_number = 0x00001234};
  auto f = encode_offline_ownership(m);
  ASSERT_TRUE(f.ok());
  // ID 0x7EF request | 0A: rsv 00, client MAC 10 | 01: R/R 0, allocate 1 |
  // 23 01 vendor 0x0123 LE | 34 12 00 00 serial 0x1234 LE
  EXPECT_EQ(hex(*f), "7EF: 0A 01 23 01 34 12 00 00");
  auto d = decode_offline_ownership(f->payload());
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(*d, m);
}

TEST(OfflineOwnership, ResponseGolden) {
  const OfflineOwnershipMessage m{.response = true,
                                  .client_mac = MacId::from_bits(63),
                                  .allocate = kOfflineRelease,
                                  .vendor_id = 0xFFFF,
                                  .serial_number = 0xFFFFFFFF};
  auto f = encode_offline_ownership(m);
  ASSERT_TRUE(f.ok());
  // ID 0x7EE response | 3F client MAC 63 | 80: R/R 1, allocate 0 | FF FF | FF FF FF FF
  EXPECT_EQ(hex(*f), "7EE: 3F 80 FF FF FF FF FF FF");
  EXPECT_EQ(*decode_offline_ownership(f->payload()), m);
}

TEST(OfflineOwnership, ReservedBitsIgnoredAndAllocateRange) {
  const ByteVec wire{0xCA, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  auto d = decode_offline_ownership(view(wire));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->client_mac.value(), 10);
  EXPECT_EQ(encode_offline_ownership({.allocate = 0x80}).error(), Errc::kOutOfRange);
}

TEST(OfflineOwnership, TruncatedAndLong) {
  const ByteVec full{0x0A, 0x01, 0x23, 0x01, 0x34, 0x12, 0x00, 0x00, 0x00};
  for (std::size_t n = 0; n < kOfflineOwnershipSize; ++n) {
    EXPECT_EQ(decode_offline_ownership(Bytes(full.data(), n)).error(), Errc::kTruncated) << n;
  }
  EXPECT_TRUE(decode_offline_ownership(Bytes(full.data(), 8)).ok());
  EXPECT_EQ(decode_offline_ownership(view(full)).error(), Errc::kMalformed);
}

TEST(OfflineOwnership, GarbageDecodesOrFailsAndRoundTrips) {
  std::mt19937 rng(11);
  for (int i = 0; i < 2000; ++i) {
    ByteVec b(static_cast<std::size_t>(rng() % 11));
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    auto d = decode_offline_ownership(view(b));
    if (b.size() != kOfflineOwnershipSize) {
      EXPECT_FALSE(d.ok());
      continue;
    }
    ASSERT_TRUE(d.ok());
    auto f = encode_offline_ownership(*d);
    ASSERT_TRUE(f.ok());
    ByteVec expected = b;
    expected[0] &= 0x3F;  // reserved bits
    EXPECT_EQ(ByteVec(f->data.begin(), f->data.begin() + f->len), expected);
  }
}

}  // namespace
}  // namespace dnbridge::devicenet
