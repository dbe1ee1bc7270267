#include "bridge/devicenet/wire/duplicate_mac.hpp"

#include <gtest/gtest.h>

#include <random>

#include "support/bytes.hpp"

namespace dnbridge::devicenet {
namespace {

using test::ByteVec;
using test::hex;
using State = DuplicateMacCheck::State;

MacId mac(unsigned v) { return MacId::from(v).value(); }
const TimePoint t0 = TimePoint{} + seconds(50);

const DuplicateMacCheck::Config kConfig{
    .window = seconds(1), .physical_port = 0, .vendor_id = 59, .serial_number = 0x12345678};

TEST(DuplicateMacMessage, RequestGolden) {
  auto f = encode_duplicate_mac(
      mac(3),
      {.response = false, .physical_port = 0, .vendor_id = 59, .serial_number = 0x12345678});
  ASSERT_TRUE(f.ok());
  // ID 0x407 + (3 << 3) | 00 request, port 0 | 3B 00 vendor 59 LE |
  // 78 56 34 12 serial 0x12345678 LE
  EXPECT_EQ(hex(*f), "41F: 00 3B 00 78 56 34 12");
}

TEST(DuplicateMacMessage, ResponseGoldenAndDecode) {
  auto f = encode_duplicate_mac(
      mac(63), {.response = true, .physical_port = 1, .vendor_id = 0x0102, .serial_number = 7});
  ASSERT_TRUE(f.ok());
  // ID 0x407 + (63 << 3) | 81 response, port 1 | 02 01 vendor | 07 00 00 00 serial
  EXPECT_EQ(hex(*f), "5FF: 81 02 01 07 00 00 00");
  auto d = decode_duplicate_mac(f->payload());
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d->response);
  EXPECT_EQ(d->physical_port, 1);
  EXPECT_EQ(d->vendor_id, 0x0102);
  EXPECT_EQ(d->serial_number, 7u);
}

TEST(DuplicateMacMessage, TruncatedLongAndOutOfRange) {
  const ByteVec full = {0x7F, 0x3B, 0x00, 0x78, 0x56, 0x34, 0x12};
  ASSERT_TRUE(decode_duplicate_mac(full).ok());
  EXPECT_EQ(decode_duplicate_mac(full)->physical_port, 0x7F);
  for (std::size_t n = 0; n < full.size(); ++n) {
    EXPECT_EQ(decode_duplicate_mac(Bytes(full.data(), n)).error(), Errc::kTruncated) << n;
  }
  ByteVec longer = full;
  longer.push_back(0);
  EXPECT_EQ(decode_duplicate_mac(longer).error(), Errc::kMalformed);
  EXPECT_EQ(encode_duplicate_mac(mac(1), {.physical_port = 128}).error(), Errc::kOutOfRange);
}

TEST(DuplicateMacMessage, EveryValidPayloadRoundTrips) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 2000; ++i) {
    ByteVec p(kDuplicateMacMessageSize);
    for (auto& b : p) b = static_cast<std::uint8_t>(byte(rng));
    auto d = decode_duplicate_mac(p);
    ASSERT_TRUE(d.ok());
    auto f = encode_duplicate_mac(mac(9), *d);
    ASSERT_TRUE(f.ok());
    EXPECT_EQ(hex(f->payload()), hex(p));
  }
}

TEST(DuplicateMacCheck, TwoQuietWindowsThenOnline) {
  DuplicateMacCheck c(mac(10), kConfig);
  EXPECT_EQ(c.state(), State::kIdle);
  EXPECT_EQ(c.deadline(), kNever);
  const can::CanFrame first = c.start(t0);
  // 0x407 + (10 << 3) = 0x457 | request, port 0 | vendor 59 | serial
  EXPECT_EQ(hex(first), "457: 00 3B 00 78 56 34 12");
  EXPECT_EQ(c.state(), State::kChecking);
  EXPECT_EQ(c.deadline(), t0 + seconds(1));
  EXPECT_FALSE(c.on_timer(t0 + milliseconds(999)).has_value());
  auto second = c.on_timer(t0 + seconds(1));
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(*second, first);
  EXPECT_EQ(c.state(), State::kChecking);
  EXPECT_EQ(c.deadline(), t0 + seconds(2));
  EXPECT_FALSE(c.on_timer(t0 + milliseconds(1999)).has_value());
  EXPECT_EQ(c.state(), State::kChecking);
  EXPECT_FALSE(c.on_timer(t0 + seconds(2)).has_value());
  EXPECT_EQ(c.state(), State::kOnline);
  EXPECT_EQ(c.deadline(), kNever);
  EXPECT_FALSE(c.on_timer(t0 + seconds(10)).has_value());
  EXPECT_EQ(c.state(), State::kOnline);
}

TEST(DuplicateMacCheck, LateTimerDoesNotShortenTheSecondWindow) {
  DuplicateMacCheck c(mac(10), {.window = milliseconds(500)});
  (void)c.start(t0);
  ASSERT_TRUE(c.on_timer(t0 + milliseconds(800)).has_value());
  EXPECT_EQ(c.deadline(), t0 + milliseconds(1300));
}

TEST(DuplicateMacCheck, RequestInFirstWindowIsADuplicate) {
  DuplicateMacCheck c(mac(10), kConfig);
  (void)c.start(t0);
  EXPECT_FALSE(c.on_message({.response = false, .vendor_id = 1, .serial_number = 2}).has_value());
  EXPECT_EQ(c.state(), State::kDuplicate);
  EXPECT_EQ(c.deadline(), kNever);
  EXPECT_FALSE(c.on_timer(t0 + seconds(5)).has_value());
  EXPECT_EQ(c.state(), State::kDuplicate);
}

TEST(DuplicateMacCheck, ResponseInSecondWindowIsADuplicate) {
  DuplicateMacCheck c(mac(10), kConfig);
  (void)c.start(t0);
  ASSERT_TRUE(c.on_timer(t0 + seconds(1)).has_value());
  EXPECT_FALSE(c.on_message({.response = true, .vendor_id = 1, .serial_number = 2}).has_value());
  EXPECT_EQ(c.state(), State::kDuplicate);
}

TEST(DuplicateMacCheck, OnlineAnswersRequestsAndFaultsOnResponses) {
  DuplicateMacCheck c(
      mac(10),
      {.window = seconds(1), .physical_port = 2, .vendor_id = 59, .serial_number = 0x01020304});
  (void)c.start(t0);
  (void)c.on_timer(t0 + seconds(1));
  (void)c.on_timer(t0 + seconds(2));
  ASSERT_EQ(c.state(), State::kOnline);
  auto answer = c.on_message({.response = false, .vendor_id = 99, .serial_number = 5});
  ASSERT_TRUE(answer.has_value());
  // 457 | 82 response, port 2 | 3B 00 vendor 59 | 04 03 02 01 serial
  EXPECT_EQ(hex(*answer), "457: 82 3B 00 04 03 02 01");
  EXPECT_EQ(c.state(), State::kOnline);
  EXPECT_FALSE(c.on_message({.response = true, .vendor_id = 99, .serial_number = 5}).has_value());
  EXPECT_EQ(c.state(), State::kDuplicate);
  // Once faulted it no longer defends the MAC.
  EXPECT_FALSE(c.on_message({.response = false}).has_value());
}

TEST(DuplicateMacCheck, IdleIgnoresMessagesAndStartRestarts) {
  DuplicateMacCheck c(mac(4), kConfig);
  EXPECT_FALSE(c.on_message({.response = false}).has_value());
  EXPECT_FALSE(c.on_message({.response = true}).has_value());
  EXPECT_EQ(c.state(), State::kIdle);
  EXPECT_FALSE(c.on_timer(t0).has_value());
  (void)c.start(t0);
  (void)c.on_message({.response = true});
  ASSERT_EQ(c.state(), State::kDuplicate);
  (void)c.start(t0 + seconds(10));  // e.g. after the fault was cleared
  EXPECT_EQ(c.state(), State::kChecking);
  EXPECT_EQ(c.deadline(), t0 + seconds(11));
  EXPECT_EQ(c.mac(), mac(4));
}

TEST(DuplicateMacCheck, OversizedPortIsMasked) {
  DuplicateMacCheck c(mac(1), {.physical_port = 0x85});
  EXPECT_EQ(c.start(t0).data[0], 0x05);
}

}  // namespace
}  // namespace dnbridge::devicenet
