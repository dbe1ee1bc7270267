#include "bridge/profiles/cdn127/device_info.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "support/bytes.hpp"

namespace dnbridge::profiles::cdn127 {
namespace {

using test::ByteVec;

// Every proper prefix of a valid value must fail as truncated.
template <class Decode>
void expect_every_prefix_truncated(Decode decode, const ByteVec& whole) {
  for (std::size_t k = 0; k < whole.size(); ++k) {
    EXPECT_EQ(decode(Bytes(whole.data(), k)).error(), Errc::kTruncated) << "prefix " << k;
  }
}

template <class Decode>
void expect_trailing_byte_malformed(Decode decode, ByteVec whole) {
  whole.push_back(0x00);
  EXPECT_EQ(decode(Bytes(whole)).error(), Errc::kMalformed);
}

// --- Identity ---------------------------------------------------------------

TEST(Revision, Golden) {
  const ByteVec wire = {0x01,   // major 1
                        0x05};  // minor 5
  EXPECT_EQ(decode_revision(wire).value(), (Revision{.major = 1, .minor = 5}));
  expect_every_prefix_truncated(decode_revision, wire);
  expect_trailing_byte_malformed(decode_revision, wire);
}

TEST(IdentityStatusTest, EachBitHasItsOdvaMeaning) {
  // WORD, little endian.
  const IdentityStatus owned = decode_identity_status(ByteVec{0x01, 0x00}).value();
  EXPECT_TRUE(owned.owned());
  EXPECT_FALSE(owned.configured());
  EXPECT_FALSE(owned.any_fault());
  EXPECT_TRUE(decode_identity_status(ByteVec{0x04, 0x00})->configured());
  EXPECT_EQ(decode_identity_status(ByteVec{0xA0, 0x00})->user_defined(), 0x0A);

  struct Fault {
    ByteVec wire;
    bool minor_rec, minor_unrec, major_rec, major_unrec;
  };
  const Fault faults[] = {
      {{0x00, 0x01}, true, false, false, false},   // bit 8: minor recoverable (DOP short)
      {{0x00, 0x02}, false, true, false, false},   // bit 9: minor unrecoverable
      {{0x00, 0x04}, false, false, true, false},   // bit 10: major recoverable (+24 V lost)
      {{0x00, 0x08}, false, false, false, true},   // bit 11: major unrecoverable (checksum)
      {{0x00, 0xF0}, false, false, false, false},  // bits 12..15 reserved
  };
  for (const Fault& f : faults) {
    const IdentityStatus s = decode_identity_status(f.wire).value();
    EXPECT_EQ(s.minor_recoverable_fault(), f.minor_rec);
    EXPECT_EQ(s.minor_unrecoverable_fault(), f.minor_unrec);
    EXPECT_EQ(s.major_recoverable_fault(), f.major_rec);
    EXPECT_EQ(s.major_unrecoverable_fault(), f.major_unrec);
    EXPECT_EQ(s.any_fault(), f.minor_rec || f.minor_unrec || f.major_rec || f.major_unrec);
    EXPECT_FALSE(s.owned());
  }
  // Round trip of the raw word.
  for (unsigned w = 0; w <= 0xFFFF; w += 0x0101) {
    const ByteVec wire = {static_cast<std::uint8_t>(w), static_cast<std::uint8_t>(w >> 8)};
    EXPECT_EQ(decode_identity_status(wire)->raw, w);
  }
  expect_every_prefix_truncated(decode_identity_status, {0x01, 0x00});
  expect_trailing_byte_malformed(decode_identity_status, {0x01, 0x00});
}

TEST(SerialNumberTest, AcceptsUintAndUdint) {
  // The manual's UINT: 2 bytes LE.
  EXPECT_EQ(decode_serial_number(ByteVec{0x34, 0x12}).value(),
            (SerialNumber{.value = 0x1234, .width = 2}));
  // ODVA's UDINT: 4 bytes LE.
  EXPECT_EQ(decode_serial_number(ByteVec{0x78, 0x56, 0x34, 0x12}).value(),
            (SerialNumber{.value = 0x12345678, .width = 4}));
  EXPECT_EQ(decode_serial_number(ByteVec{}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_serial_number(ByteVec{0x01}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_serial_number(ByteVec{0x01, 0x02, 0x03}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_serial_number(ByteVec{1, 2, 3, 4, 5}).error(), Errc::kMalformed);
  EXPECT_EQ(decode_serial_number(ByteVec(8, 0xFF)).error(), Errc::kMalformed);
}

TEST(ShortStringTest, ProductNameGolden) {
  const ByteVec wire = {0x06,                                 // length 6
                        0x43, 0x44, 0x4E, 0x31, 0x32, 0x37};  // "CDN127"
  const auto name = decode_product_name(wire);
  ASSERT_TRUE(name.ok());
  EXPECT_EQ(name->view(), "CDN127");
  EXPECT_EQ(name->size(), 6u);
  expect_every_prefix_truncated(decode_short_string, wire);
  expect_trailing_byte_malformed(decode_short_string, wire);
}

TEST(ShortStringTest, EmptyAndLongestStrings) {
  EXPECT_EQ(decode_short_string(ByteVec{0x00})->view(), "");
  ByteVec longest = {0xFF};
  for (int i = 0; i < 255; ++i) longest.push_back(static_cast<std::uint8_t>('A' + i % 26));
  const auto s = decode_short_string(longest);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->size(), 255u);
  EXPECT_EQ(s->view().substr(0, 3), "ABC");
  EXPECT_EQ(s->view().back(), 'U');  // 254 % 26 = 20
  // The Device Supervisor's manufacturer name, "D.I.P. Inc.".
  const ByteVec dip = {0x0B, 'D', '.', 'I', '.', 'P', '.', ' ', 'I', 'n', 'c', '.'};
  EXPECT_EQ(decode_short_string(dip)->view(), "D.I.P. Inc.");
  // Round trip through a test-side encoder for every length.
  for (std::size_t n = 0; n <= 255; ++n) {
    ByteVec wire = {static_cast<std::uint8_t>(n)};
    for (std::size_t i = 0; i < n; ++i) wire.push_back(static_cast<std::uint8_t>(i * 7));
    const auto d = decode_short_string(wire);
    ASSERT_TRUE(d.ok());
    ASSERT_EQ(d->size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(static_cast<std::uint8_t>(d->view()[i]), static_cast<std::uint8_t>(i * 7));
    }
  }
}

TEST(IdentityStateTest, NamedAndReservedStates) {
  const char* names[] = {"non-existent",
                         "self test",
                         "standby",
                         "operating",
                         "major recoverable fault",
                         "major unrecoverable fault"};
  for (std::uint8_t v = 0; v <= 5; ++v) {
    const auto s = decode_identity_state(ByteVec{v});
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(static_cast<std::uint8_t>(*s), v);
    EXPECT_EQ(to_string(*s), names[v]);
  }
  EXPECT_EQ(*decode_identity_state(ByteVec{0x03}), IdentityState::kOperating);
  EXPECT_EQ(to_string(decode_identity_state(ByteVec{6}).value()), "reserved");
  EXPECT_EQ(to_string(decode_identity_state(ByteVec{255}).value()), "reserved");
  EXPECT_EQ(decode_identity_state(ByteVec{}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_identity_state(ByteVec{3, 0}).error(), Errc::kMalformed);
}

// --- Device Supervisor ------------------------------------------------------

TEST(SupervisorDeviceStatusTest, NamedAndRangedValues) {
  const char* names[] = {"undefined", "self testing", "idle",          "self-test exception",
                         "executing", "abort",        "critical fault"};
  for (std::uint8_t v = 0; v <= 6; ++v) {
    EXPECT_EQ(to_string(decode_supervisor_device_status(ByteVec{v}).value()), names[v]);
  }
  EXPECT_EQ(*decode_supervisor_device_status(ByteVec{4}), SupervisorDeviceStatus::kExecuting);
  for (unsigned v : {7U, 50U}) {
    EXPECT_EQ(to_string(static_cast<SupervisorDeviceStatus>(v)), "reserved") << v;
  }
  for (unsigned v : {51U, 99U}) {
    EXPECT_EQ(to_string(static_cast<SupervisorDeviceStatus>(v)), "device specific") << v;
  }
  for (unsigned v : {100U, 255U}) {
    EXPECT_EQ(to_string(static_cast<SupervisorDeviceStatus>(v)), "vendor specific") << v;
  }
  EXPECT_EQ(decode_supervisor_device_status(ByteVec{}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_supervisor_device_status(ByteVec{4, 4}).error(), Errc::kMalformed);
}

TEST(SupervisorExceptionStatus, AttributeIsOneByte) {
  EXPECT_EQ(decode_exception_status(ByteVec{0x22}).value(),
            (ExceptionStatus{.alarm_device_specific = true, .warning_device_specific = true}));
  EXPECT_EQ(decode_exception_status(ByteVec{}).error(), Errc::kTruncated);
  EXPECT_EQ(decode_exception_status(ByteVec{0, 0}).error(), Errc::kMalformed);
}

// Attribute 13 as the manual's table lays it out.
const ByteVec kExceptionDetail = {
    0x02, 0x00, 0x00,  // common detail: size 2, BYTE[2]
    0x08,              // device detail size 8
    0x08, 0x05,        //   DIP: 8 status bits; DIP 1 and DIP 3 faulted
    0x08, 0x00,        //   DOP: 8 status bits; none
    0x02, 0x02,        //   AIP: 2 status bits; AIP 2 faulted
    0x01, 0x01,        //   AOP: 1 status bit; AOP 1 faulted
    0x01, 0x40,        // manufacturer detail: size 1, 0x40
};

TEST(SupervisorDetailTest, ExceptionDetailGolden) {
  const auto d = decode_exception_detail(kExceptionDetail);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(test::hex(d->common.view()), "00 00");
  EXPECT_EQ(d->device_size, 8);
  ASSERT_EQ(d->point_count, 4u);
  const PointStatus& dip = d->points[SupervisorDetail::kDip];
  EXPECT_EQ(dip.count, 8);
  EXPECT_TRUE(dip.fault(0));
  EXPECT_FALSE(dip.fault(1));
  EXPECT_TRUE(dip.fault(2));
  EXPECT_FALSE(dip.fault(8));  // past the count
  EXPECT_TRUE(dip.any_fault());
  EXPECT_EQ(d->points[SupervisorDetail::kDop].count, 8);
  EXPECT_FALSE(d->points[SupervisorDetail::kDop].any_fault());
  EXPECT_EQ(d->points[SupervisorDetail::kAip].count, 2);
  EXPECT_FALSE(d->points[SupervisorDetail::kAip].fault(0));
  EXPECT_TRUE(d->points[SupervisorDetail::kAip].fault(1));
  EXPECT_EQ(d->points[SupervisorDetail::kAop].count, 1);
  EXPECT_TRUE(d->points[SupervisorDetail::kAop].fault(0));
  EXPECT_TRUE(d->device_extra.empty());
  EXPECT_EQ(test::hex(d->manufacturer.view()), "40");
  expect_every_prefix_truncated(decode_exception_detail, kExceptionDetail);
  expect_trailing_byte_malformed(decode_exception_detail, kExceptionDetail);
}

TEST(SupervisorDetailTest, WarningDetailGolden) {
  const ByteVec wire = {
      0x02, 0x01, 0x00,  // common detail: size 2, BYTE[2]
      0x00,              // device detail size 0: no warning status for GP I/O
      0x01, 0x03,        // manufacturer detail: size 1, 0x03
  };
  const auto d = decode_warning_detail(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(test::hex(d->common.view()), "01 00");
  EXPECT_EQ(d->device_size, 0);
  EXPECT_EQ(d->point_count, 0u);
  EXPECT_EQ(test::hex(d->manufacturer.view()), "03");
  expect_every_prefix_truncated(decode_warning_detail, wire);
  expect_trailing_byte_malformed(decode_warning_detail, wire);
}

TEST(SupervisorDetailTest, ToleratesWhatTheDeviceReports) {
  // 7 DIPs, 16 DOPs (two bytes), no AIP/AOP structures, a 3-byte common
  // detail and an empty manufacturer detail.
  const ByteVec wire = {
      0x03, 0xAA, 0xBB, 0xCC,  // common: size 3
      0x05,                    // device size 5
      0x07, 0x40,              //   DIP: 7 bits; DIP 7 faulted
      0x10, 0x00, 0x80,        //   DOP: 16 bits; DOP 16 faulted
      0x00,                    // manufacturer: size 0
  };
  const auto d = decode_exception_detail(wire);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->common.size(), 3u);
  EXPECT_EQ(d->point_count, 2u);
  EXPECT_EQ(d->points[SupervisorDetail::kDip].count, 7);
  EXPECT_TRUE(d->points[SupervisorDetail::kDip].fault(6));
  EXPECT_TRUE(d->points[SupervisorDetail::kDop].fault(15));
  EXPECT_FALSE(d->points[SupervisorDetail::kDop].fault(14));
  EXPECT_EQ(d->points[SupervisorDetail::kAip], PointStatus{});
  EXPECT_TRUE(d->manufacturer.empty());
  expect_every_prefix_truncated(decode_exception_detail, wire);

  // Bytes after the fourth structure are kept, not refused.
  const ByteVec extra = {
      0x00,                    // common: size 0
      0x0A,                    // device size 10
      0x01, 0x00, 0x01, 0x00,  //   DIP, DOP: 1 bit each, no fault
      0x01, 0x00, 0x01, 0x00,  //   AIP, AOP: 1 bit each, no fault
      0xDE, 0xAD,              //   2 bytes the manual does not describe
      0x00,                    // manufacturer: size 0
  };
  const auto e = decode_exception_detail(extra);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->point_count, 4u);
  EXPECT_EQ(test::hex(e->device_extra.view()), "DE AD");
}

TEST(SupervisorDetailTest, PointStructureOverrunningItsDeviceDetailIsMalformed) {
  const ByteVec wire = {
      0x00,        // common: size 0
      0x02,        // device size 2
      0x10, 0xFF,  //   DIP: 16 bits need 2 bytes, only 1 inside the device detail
      0x00,        // manufacturer: size 0 (or the DIP's second byte)
  };
  EXPECT_EQ(decode_exception_detail(wire).error(), Errc::kMalformed);
}

// A test-side encoder for the round trip.
ByteVec encode_detail(const ByteVec& common,
                      const std::vector<std::pair<std::uint8_t, ByteVec>>& points,
                      const ByteVec& manufacturer) {
  ByteVec device;
  for (const auto& [count, bits] : points) {
    device.push_back(count);
    device.insert(device.end(), bits.begin(), bits.end());
  }
  ByteVec out = {static_cast<std::uint8_t>(common.size())};
  out.insert(out.end(), common.begin(), common.end());
  out.push_back(static_cast<std::uint8_t>(device.size()));
  out.insert(out.end(), device.begin(), device.end());
  out.push_back(static_cast<std::uint8_t>(manufacturer.size()));
  out.insert(out.end(), manufacturer.begin(), manufacturer.end());
  return out;
}

TEST(SupervisorDetailTest, RoundTripsRandomStructures) {
  std::mt19937 rng(13);
  std::uniform_int_distribution<unsigned> byte(0, 255), small(0, 6), groups(0, 4), count(0, 40);
  for (int trial = 0; trial < 500; ++trial) {
    ByteVec common(small(rng)), manufacturer(small(rng));
    for (auto& b : common) b = static_cast<std::uint8_t>(byte(rng));
    for (auto& b : manufacturer) b = static_cast<std::uint8_t>(byte(rng));
    std::vector<std::pair<std::uint8_t, ByteVec>> points(groups(rng));
    for (auto& [n, bits] : points) {
      n = static_cast<std::uint8_t>(count(rng));
      bits.resize((n + 7U) / 8U);
      for (auto& b : bits) b = static_cast<std::uint8_t>(byte(rng));
    }
    const ByteVec wire = encode_detail(common, points, manufacturer);
    const auto d = decode_supervisor_detail(wire);
    ASSERT_TRUE(d.ok()) << test::hex(wire);
    EXPECT_EQ(ByteVec(d->common.view().begin(), d->common.view().end()), common);
    EXPECT_EQ(ByteVec(d->manufacturer.view().begin(), d->manufacturer.view().end()), manufacturer);
    ASSERT_EQ(d->point_count, points.size());
    for (std::size_t g = 0; g < points.size(); ++g) {
      EXPECT_EQ(d->points[g].count, points[g].first);
      for (std::size_t i = 0; i < points[g].first; ++i) {
        EXPECT_EQ(d->points[g].fault(i), ((points[g].second[i / 8] >> (i % 8)) & 1) != 0);
      }
    }
    EXPECT_TRUE(d->device_extra.empty());
  }
}

TEST(DeviceInfoGarbage, RandomBytesFailCleanlyOrDecodeConsistently) {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<unsigned> byte(0, 255), len(0, 24);
  int decoded = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    ByteVec g(len(rng));
    for (auto& b : g) b = static_cast<std::uint8_t>(byte(rng) % 12);  // small sizes, often valid
    const auto d = decode_supervisor_detail(g);
    if (d.ok()) {
      ++decoded;
      // The sizes account for every byte.
      EXPECT_EQ(3 + d->common.size() + d->device_size + d->manufacturer.size(), g.size());
    }
    const auto s = decode_short_string(g);
    EXPECT_EQ(s.ok(), !g.empty() && g[0] + 1U == g.size());
    EXPECT_EQ(decode_revision(g).ok(), g.size() == 2);
    EXPECT_EQ(decode_serial_number(g).ok(), g.size() == 2 || g.size() == 4);
    EXPECT_EQ(decode_identity_state(g).ok(), g.size() == 1);
  }
  EXPECT_GT(decoded, 0);  // the garbage does reach the success path sometimes
}

}  // namespace
}  // namespace dnbridge::profiles::cdn127
