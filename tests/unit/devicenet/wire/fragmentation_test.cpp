#include "bridge/devicenet/wire/fragmentation.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "bridge/devicenet/wire/identifier.hpp"
#include "support/bytes.hpp"

namespace dnbridge::devicenet {
namespace {

using test::ByteVec;
using test::hex;
using Step = ExplicitFragmentSender::Step;
using Outcome = ExplicitReassembler::Outcome;
using IoOutcome = IoReassembler::Outcome;

MacId mac(unsigned v) { return MacId::from(v).value(); }
const TimePoint t0 = TimePoint{} + seconds(100);

ByteVec sequence(std::size_t n, std::uint8_t first = 1) {
  ByteVec v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(first + i);
  return v;
}

ByteVec copy(Bytes b) { return ByteVec(b.begin(), b.end()); }

// The ack a receiver sends for `count`: [header with Frag][C0 | count][status].
ByteVec ack_for(std::uint8_t header, std::uint8_t count, std::uint8_t status = 0) {
  return {static_cast<std::uint8_t>(header | 0x80), static_cast<std::uint8_t>(0xC0 | count),
          status};
}

// Every frame the sender produces for `message` when each ack comes at once.
std::vector<ByteVec> all_fragments(Bytes message, ExplicitHeader header = {}) {
  ExplicitFragmentSender sender;
  std::vector<ByteVec> frames;
  if (!sender.start(header, message, t0).ok()) return frames;
  for (;;) {
    frames.push_back(copy(sender.frame()));
    const Step s = sender.on_ack(ack_for(sender.frame()[0], sender.frame()[1] & 0x3F), t0);
    if (s != Step::kSend) break;
  }
  return frames;
}

// ---------------------------------------------------------------------------

TEST(FragmentByte, TypeAndCount) {
  EXPECT_EQ(encode_fragment_byte({FragmentType::kFirst, 0}), 0x00);
  EXPECT_EQ(encode_fragment_byte({FragmentType::kMiddle, 1}), 0x41);
  EXPECT_EQ(encode_fragment_byte({FragmentType::kLast, 1}), 0x81);
  EXPECT_EQ(encode_fragment_byte({FragmentType::kAck, 63}), 0xFF);
  EXPECT_EQ(decode_fragment_byte(0xC1), (FragmentByte{FragmentType::kAck, 1}));
  for (unsigned b = 0; b <= 0xFF; ++b) {
    const auto byte = static_cast<std::uint8_t>(b);
    EXPECT_EQ(encode_fragment_byte(decode_fragment_byte(byte)), byte);
  }
}

// ---------------------------------------------------------------------------
// The 1760-DNET worked example (bridge/PROTOCOL.md §5): master MAC 0, slave 3.

TEST(ExplicitFragmentation, Rockwell1760DnetRequestFirstFragment) {
  // The example shows the request's first fragment only: 32 64 01 93 05 00.
  // Its tail is not in the example; EE FF stand for it (a fragmented request
  // has at least 7 bytes).
  const ByteVec request = {0x32, 0x64, 0x01, 0x93, 0x05, 0x00, 0xEE, 0xFF};
  ExplicitFragmentSender master;
  ASSERT_TRUE(master.start({.frag = false, .xid = false, .mac = mac(0)}, request, t0).ok());
  EXPECT_EQ(group2_id(mac(3), Group2Message::kMasterExplicitRequest), 0x41Cu);
  // 80 header: Frag 1, XID 0, MAC 0 (master) | 00 first fragment, count 0 |
  // 32 64 01 93 05 00 first 6 message bytes
  EXPECT_EQ(hex(master.frame()), "80 00 32 64 01 93 05 00");

  // The slave's reassembler acks it: 41B: 80 C0 00.
  ExplicitReassembler slave;
  EXPECT_EQ(slave.on_fragment(master.frame()), Outcome::kAccepted);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kSlaveExplicitResponse), 0x41Bu);
  // 80 header Frag, MAC 0 | C0 ack, count 0 | 00 status success
  EXPECT_EQ(hex(slave.ack()), "80 C0 00");

  ASSERT_EQ(master.on_ack(slave.ack(), t0), Step::kSend);
  // 80 header | 81 last fragment, count 1 | EE FF rest of the message
  EXPECT_EQ(hex(master.frame()), "80 81 EE FF");
  EXPECT_EQ(slave.on_fragment(master.frame()), Outcome::kComplete);
  EXPECT_EQ(hex(slave.ack()), "80 C1 00");
  EXPECT_EQ(master.on_ack(slave.ack(), t0), Step::kComplete);
  EXPECT_EQ(copy(slave.message()), request);
}

TEST(ExplicitFragmentation, Rockwell1760DnetResponseReassembled) {
  ExplicitReassembler master;
  // 41B: 80 header (Frag, MAC 0) | 00 first, count 0 | B2 = 0x32 | R/R, then 5
  // bytes the example elides (11 22 33 44 55 stand for them).
  const ByteVec first = {0x80, 0x00, 0xB2, 0x11, 0x22, 0x33, 0x44, 0x55};
  EXPECT_EQ(master.on_fragment(first), Outcome::kAccepted);
  EXPECT_EQ(hex(master.ack()), "80 C0 00");  // 41C: ack count 0, success
  EXPECT_TRUE(master.in_progress());
  // 41B: 80 header | 81 last, count 1 | 0D 05 04 the last 3 bytes
  const ByteVec last = {0x80, 0x81, 0x0D, 0x05, 0x04};
  EXPECT_EQ(master.on_fragment(last), Outcome::kComplete);
  EXPECT_EQ(hex(master.ack()), "80 C1 00");  // 41C: ack count 1, success
  EXPECT_FALSE(master.in_progress());
  EXPECT_EQ(hex(master.message()), "B2 11 22 33 44 55 0D 05 04");
  ASSERT_FALSE(master.message().empty());
  EXPECT_EQ(master.message()[0], 0xB2);
}

// ---------------------------------------------------------------------------
// Sender.

TEST(ExplicitFragmentSender, SplitsSevenTwelveThirteenBytes) {
  const ByteVec m7 = sequence(7), m12 = sequence(12), m13 = sequence(13);
  auto f7 = all_fragments(m7, {.frag = false, .xid = true, .mac = mac(10)});
  ASSERT_EQ(f7.size(), 2u);
  EXPECT_EQ(hex(f7[0]), "CA 00 01 02 03 04 05 06");  // Frag|XID|MAC 10, first 0, 6 bytes
  EXPECT_EQ(hex(f7[1]), "CA 81 07");                 // last 1, 1 byte

  auto f12 = all_fragments(m12, {.frag = false, .xid = false, .mac = mac(10)});
  ASSERT_EQ(f12.size(), 2u);
  EXPECT_EQ(hex(f12[0]), "8A 00 01 02 03 04 05 06");
  EXPECT_EQ(hex(f12[1]), "8A 81 07 08 09 0A 0B 0C");  // a full last fragment

  auto f13 = all_fragments(m13, {.frag = false, .xid = false, .mac = mac(10)});
  ASSERT_EQ(f13.size(), 3u);
  EXPECT_EQ(hex(f13[0]), "8A 00 01 02 03 04 05 06");
  EXPECT_EQ(hex(f13[1]), "8A 41 07 08 09 0A 0B 0C");  // middle 1
  EXPECT_EQ(hex(f13[2]), "8A 82 0D");                 // last 2
}

TEST(ExplicitFragmentSender, MessageThatFitsOneFragmentStillGoesAsFirstAndLast) {
  const ByteVec m3 = {0x0E, 0x01, 0x01};
  auto f = all_fragments(m3);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(hex(f[0]), "80 00 0E 01");  // first: all but the final byte
  EXPECT_EQ(hex(f[1]), "80 81 01");     // last: the final byte
  const ByteVec m1 = {0xCC};
  auto g = all_fragments(m1);
  ASSERT_EQ(g.size(), 2u);
  EXPECT_EQ(hex(g[0]), "80 00");  // an empty first fragment
  EXPECT_EQ(hex(g[1]), "80 81 CC");
  // A receiver following the rules gets the message back.
  for (std::size_t n = 1; n <= 6; ++n) {
    ExplicitReassembler r;
    const ByteVec m = sequence(n);
    Outcome last = Outcome::kDropped;
    for (const auto& frame : all_fragments(m)) last = r.on_fragment(frame);
    EXPECT_EQ(last, Outcome::kComplete) << n;
    EXPECT_EQ(copy(r.message()), m) << n;
  }
}

TEST(ExplicitFragmentSender, RefusesEmptyAndOverlongMessages) {
  ExplicitFragmentSender s;
  const ByteVec empty, max = sequence(kMaxExplicitMessage),
                       over = sequence(kMaxExplicitMessage + 1);
  EXPECT_EQ(s.start({}, empty, t0).error(), Errc::kOutOfRange);
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.start({}, over, t0).error(), Errc::kOutOfRange);
  EXPECT_FALSE(s.active());
  EXPECT_TRUE(s.start({}, max, t0).ok());
  EXPECT_TRUE(s.active());
}

TEST(ExplicitFragmentSender, ResendsOnceOnTimeoutThenAborts) {
  ExplicitFragmentSender s({.ack_timeout = seconds(1), .resends = 1});
  const ByteVec m = sequence(10);
  ASSERT_TRUE(s.start({.frag = false, .xid = false, .mac = mac(0)}, m, t0).ok());
  const ByteVec first = copy(s.frame());
  EXPECT_EQ(s.deadline(), t0 + seconds(1));
  EXPECT_EQ(s.on_timer(t0 + milliseconds(999)), Step::kNone);  // not yet
  EXPECT_EQ(s.on_timer(t0 + seconds(1)), Step::kSend);
  EXPECT_EQ(copy(s.frame()), first);  // the same bytes again
  EXPECT_EQ(s.deadline(), t0 + seconds(2));
  EXPECT_TRUE(s.active());
  EXPECT_EQ(s.on_timer(t0 + seconds(2)), Step::kFailed);
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.failure(), Errc::kAborted);
  EXPECT_EQ(s.deadline(), kNever);
  // Afterwards nothing happens.
  EXPECT_EQ(s.on_timer(t0 + seconds(5)), Step::kNone);
  EXPECT_EQ(s.on_ack(ack_for(0x80, 0), t0 + seconds(5)), Step::kNone);
}

TEST(ExplicitFragmentSender, EachFragmentGetsItsOwnResend) {
  ExplicitFragmentSender s;
  const ByteVec m = sequence(13);
  ASSERT_TRUE(s.start({}, m, t0).ok());
  ASSERT_EQ(s.on_timer(t0 + seconds(1)), Step::kSend);  // resend of the first
  ASSERT_EQ(s.on_ack(ack_for(0x80, 0), t0 + milliseconds(1500)), Step::kSend);
  EXPECT_EQ(s.deadline(), t0 + milliseconds(2500));             // deadline from the ack
  EXPECT_EQ(s.on_timer(t0 + milliseconds(2500)), Step::kSend);  // the middle's resend
  EXPECT_EQ(hex(s.frame()), "80 41 07 08 09 0A 0B 0C");
  EXPECT_EQ(s.on_timer(t0 + milliseconds(3500)), Step::kFailed);
  EXPECT_EQ(s.failure(), Errc::kAborted);
}

TEST(ExplicitFragmentSender, ErrorAckStatusFailsWithDeviceError) {
  ExplicitFragmentSender s;
  const ByteVec m = sequence(20);
  ASSERT_TRUE(s.start({}, m, t0).ok());
  EXPECT_EQ(s.on_ack(ack_for(0x80, 0, 1), t0), Step::kFailed);  // status 1: error
  EXPECT_EQ(s.failure(), Errc::kDeviceError);
  EXPECT_FALSE(s.active());
}

TEST(ExplicitFragmentSender, IgnoresAcksForOtherCountsAndUnparsableAcks) {
  ExplicitFragmentSender s;
  const ByteVec m = sequence(20);
  ASSERT_TRUE(s.start({}, m, t0).ok());
  const ByteVec first = copy(s.frame());
  const ByteVec wrong_count = ack_for(0x80, 1);
  const ByteVec short_ack = {0x80, 0xC0};
  const ByteVec no_frag = {0x00, 0xC0, 0x00};
  const ByteVec not_ack = {0x80, 0x40, 0x00};
  const ByteVec empty;
  for (const ByteVec* a : {&wrong_count, &short_ack, &no_frag, &not_ack, &empty}) {
    EXPECT_EQ(s.on_ack(*a, t0), Step::kNone) << hex(*a);
    EXPECT_TRUE(s.active());
    EXPECT_EQ(copy(s.frame()), first);
    EXPECT_EQ(s.deadline(), t0 + seconds(1));
  }
  // A wrong-count ack with an error status is ignored too.
  EXPECT_EQ(s.on_ack(ack_for(0x80, 5, 1), t0), Step::kNone);
  EXPECT_EQ(s.on_ack(ack_for(0x80, 0), t0), Step::kSend);
}

TEST(ExplicitFragmentSender, CountWrapsModulo64) {
  const ByteVec m = sequence(500);
  auto frames = all_fragments(m);
  ASSERT_EQ(frames.size(), 84u);  // 83 full fragments + 2 bytes
  ByteVec joined;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FragmentByte f = decode_fragment_byte(frames[i][1]);
    EXPECT_EQ(f.count, i % 64) << i;
    const FragmentType expected = i == 0                   ? FragmentType::kFirst
                                  : i + 1 == frames.size() ? FragmentType::kLast
                                                           : FragmentType::kMiddle;
    EXPECT_EQ(f.type, expected) << i;
    joined.insert(joined.end(), frames[i].begin() + 2, frames[i].end());
  }
  EXPECT_EQ(hex(frames[64]), "80 40 81 82 83 84 85 86");  // count back to 0, a middle
  EXPECT_EQ(frames.back().size(), 4u);                    // last: header, fragment byte, 2 bytes
  EXPECT_EQ(joined, m);
}

TEST(ExplicitFragmentSender, CancelStopsTheTransfer) {
  ExplicitFragmentSender s;
  const ByteVec m = sequence(20);
  ASSERT_TRUE(s.start({}, m, t0).ok());
  s.cancel();
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.failure(), Errc::kAborted);
  EXPECT_EQ(s.on_ack(ack_for(0x80, 0), t0), Step::kNone);
  EXPECT_EQ(s.on_timer(t0 + seconds(10)), Step::kNone);
}

// ---------------------------------------------------------------------------
// Reassembler rules.

struct Frag {
  std::uint8_t fragment_byte;
  ByteVec data;
  ByteVec payload(std::uint8_t header = 0x80) const {
    ByteVec p = {header, fragment_byte};
    p.insert(p.end(), data.begin(), data.end());
    return p;
  }
};
const Frag kFirst{0x00, {1, 2, 3, 4, 5, 6}};
const Frag kMiddle1{0x41, {7, 8, 9, 10, 11, 12}};
const Frag kMiddle2{0x42, {13, 14, 15, 16, 17, 18}};
const Frag kLast2{0x82, {19, 20}};
const Frag kLast3{0x83, {21}};

TEST(ExplicitReassembler, FirstWithNonZeroCountIsDroppedWithoutAck) {
  ExplicitReassembler r;
  EXPECT_EQ(r.on_fragment(Frag{0x05, {1, 2}}.payload()), Outcome::kDropped);
  EXPECT_TRUE(r.ack().empty());
  EXPECT_FALSE(r.in_progress());
  // While a transfer is in progress, it is dropped and the transfer goes on.
  EXPECT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(Frag{0x01, {9}}.payload()), Outcome::kDropped);
  EXPECT_TRUE(r.ack().empty());
  EXPECT_TRUE(r.in_progress());
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(kMiddle2.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(kLast3.payload()), Outcome::kComplete);
  EXPECT_EQ(copy(r.message()),
            (ByteVec{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 21}));
}

TEST(ExplicitReassembler, RepeatIsReackedWithoutAppending) {
  ExplicitReassembler r;
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  // The first again (its ack was lost): re-acked, nothing appended.
  EXPECT_EQ(r.on_fragment(kFirst.payload()), Outcome::kRepeated);
  EXPECT_EQ(hex(r.ack()), "80 C0 00");
  ASSERT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kRepeated);
  EXPECT_EQ(hex(r.ack()), "80 C1 00");
  EXPECT_TRUE(r.in_progress());
  ASSERT_EQ(r.on_fragment(kLast2.payload()), Outcome::kComplete);
  EXPECT_EQ(r.message().size(), 14u);
  // The last again after completion: re-acked so the sender does not give up.
  EXPECT_EQ(r.on_fragment(kLast2.payload()), Outcome::kRepeated);
  EXPECT_EQ(hex(r.ack()), "80 C2 00");
  EXPECT_EQ(r.message().size(), 14u);
  // But not a middle of the finished transfer.
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kDropped);
  EXPECT_TRUE(r.ack().empty());
}

TEST(ExplicitReassembler, CountMismatchResetsWithoutAck) {
  ExplicitReassembler r;
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(kMiddle2.payload()), Outcome::kRestarted);  // 2 where 1 was due
  EXPECT_TRUE(r.ack().empty());
  EXPECT_FALSE(r.in_progress());
  // The rest of that transfer has nothing to attach to.
  EXPECT_EQ(r.on_fragment(kLast3.payload()), Outcome::kDropped);
  // A previous-type fragment with the previous count but another type is no repeat.
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(Frag{0x80, {1}}.payload()), Outcome::kRestarted);  // last, count 0
}

TEST(ExplicitReassembler, MiddleOrLastWithoutFirstIsDroppedWithoutAck) {
  ExplicitReassembler r;
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kDropped);
  EXPECT_TRUE(r.ack().empty());
  EXPECT_EQ(r.on_fragment(Frag{0x80, {1}}.payload()), Outcome::kDropped);
  EXPECT_TRUE(r.ack().empty());
  EXPECT_FALSE(r.in_progress());
  EXPECT_TRUE(r.message().empty());
}

TEST(ExplicitReassembler, NewFirstRestartsTheTransfer) {
  ExplicitReassembler r;
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  ASSERT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kAccepted);
  const Frag other{0x00, {0xA1, 0xA2, 0xA3}};
  EXPECT_EQ(r.on_fragment(other.payload()), Outcome::kRestarted);
  EXPECT_TRUE(r.in_progress());
  EXPECT_EQ(hex(r.ack()), "80 C0 00");  // the new first is acked
  EXPECT_EQ(r.on_fragment(Frag{0x81, {0xA4}}.payload()), Outcome::kComplete);
  EXPECT_EQ(hex(r.message()), "A1 A2 A3 A4");
  // A first that differs from the only fragment received restarts as well.
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(other.payload()), Outcome::kRestarted);
  EXPECT_EQ(hex(r.message()), "A1 A2 A3");
}

TEST(ExplicitReassembler, OverflowAcksWithErrorStatusAndResets) {
  ExplicitReassembler r(10);
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kOverflow);  // 12 > 10
  EXPECT_EQ(hex(r.ack()), "80 C1 01");  // ack count 1, status 1 (error)
  EXPECT_FALSE(r.in_progress());
  EXPECT_EQ(r.on_fragment(kMiddle2.payload()), Outcome::kDropped);

  ExplicitReassembler tiny(4);
  EXPECT_EQ(tiny.on_fragment(kFirst.payload()), Outcome::kOverflow);
  EXPECT_EQ(hex(tiny.ack()), "80 C0 01");
  EXPECT_FALSE(tiny.in_progress());

  ExplicitReassembler exact(12);
  ASSERT_EQ(exact.on_fragment(kFirst.payload()), Outcome::kAccepted);
  EXPECT_EQ(exact.on_fragment(Frag{0x81, kMiddle1.data}.payload()), Outcome::kComplete);
  EXPECT_EQ(exact.message().size(), 12u);

  // The sender gives up on the error ack.
  ExplicitFragmentSender s;
  ExplicitReassembler small(8);
  const ByteVec m = sequence(20);
  ASSERT_TRUE(s.start({}, m, t0).ok());
  ASSERT_EQ(small.on_fragment(s.frame()), Outcome::kAccepted);
  ASSERT_EQ(s.on_ack(small.ack(), t0), Step::kSend);
  ASSERT_EQ(small.on_fragment(s.frame()), Outcome::kOverflow);
  EXPECT_EQ(s.on_ack(small.ack(), t0), Step::kFailed);
  EXPECT_EQ(s.failure(), Errc::kDeviceError);
}

TEST(ExplicitReassembler, AckEchoesTheHeader) {
  ExplicitReassembler r;
  // C5: Frag, XID, MAC 5
  ASSERT_EQ(r.on_fragment(kFirst.payload(0xC5)), Outcome::kAccepted);
  EXPECT_EQ(hex(r.ack()), "C5 C0 00");
}

TEST(ExplicitReassembler, UnparsableFramesAreDropped) {
  ExplicitReassembler r;
  const ByteVec empty, one = {0x80}, no_frag = {0x00, 0x00, 0x01}, ack = {0x80, 0xC0, 0x00},
                       too_long = {0x80, 0x00, 1, 2, 3, 4, 5, 6, 7};
  for (const ByteVec* p : {&empty, &one, &no_frag, &ack, &too_long}) {
    EXPECT_EQ(r.on_fragment(*p), Outcome::kDropped) << hex(*p);
    EXPECT_TRUE(r.ack().empty());
    EXPECT_FALSE(r.in_progress());
  }
}

TEST(ExplicitReassembler, ResetForgetsEverything) {
  ExplicitReassembler r;
  ASSERT_EQ(r.on_fragment(kFirst.payload()), Outcome::kAccepted);
  r.reset();
  EXPECT_FALSE(r.in_progress());
  EXPECT_TRUE(r.ack().empty());
  EXPECT_TRUE(r.message().empty());
  EXPECT_EQ(r.on_fragment(kMiddle1.payload()), Outcome::kDropped);
}

// Random messages through sender and reassembler come back unchanged; some
// acks are lost once, so resends and re-acks are exercised as well.
TEST(ExplicitFragmentation, RandomMessagesRoundTrip) {
  std::mt19937 rng(0xD0A7u);
  std::uniform_int_distribution<std::size_t> size(1, kMaxExplicitMessage);
  std::uniform_int_distribution<int> byte(0, 255);
  std::bernoulli_distribution lose_ack(0.1);
  for (int i = 0; i < 300; ++i) {
    ByteVec m(size(rng));
    for (auto& b : m) b = static_cast<std::uint8_t>(byte(rng));
    const ExplicitHeader header{
        .frag = false, .xid = (i & 1) != 0, .mac = MacId::from_bits(static_cast<unsigned>(i))};
    ExplicitFragmentSender sender;
    ExplicitReassembler receiver;
    TimePoint now = t0;
    ASSERT_TRUE(sender.start(header, m, now).ok());
    Step step = Step::kSend;
    Outcome outcome = Outcome::kDropped;
    int frames = 0;
    while (step == Step::kSend) {
      ASSERT_LT(++frames, 400);
      outcome = receiver.on_fragment(sender.frame());
      ASSERT_FALSE(receiver.ack().empty());
      if (lose_ack(rng)) {
        now = sender.deadline();
        step = sender.on_timer(now);  // the resend
        ASSERT_EQ(step, Step::kSend);
        ASSERT_EQ(receiver.on_fragment(sender.frame()), Outcome::kRepeated);
      }
      now += milliseconds(1);
      step = sender.on_ack(receiver.ack(), now);
    }
    ASSERT_EQ(step, Step::kComplete) << i;
    ASSERT_FALSE(receiver.in_progress());
    ASSERT_EQ(copy(receiver.message()), m) << i;
    (void)outcome;
  }
}

// Garbage frames never break the reassembler's invariants.
TEST(ExplicitReassembler, GarbageKeepsInvariants) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 10);
  ExplicitReassembler r(40);
  for (int i = 0; i < 50000; ++i) {
    ByteVec p(length(rng));
    for (auto& b : p) b = static_cast<std::uint8_t>(byte(rng));
    // Bias towards fragments so that transfers make progress.
    if (p.size() >= 2) p[0] |= 0x80;
    if (p.size() >= 2 && (i % 3) != 0) p[1] &= 0x83;
    const Outcome o = r.on_fragment(p);
    EXPECT_LE(r.message().size(), 40u);
    if (!r.ack().empty()) {
      ASSERT_EQ(r.ack().size(), 3u);
      EXPECT_EQ(r.ack()[1] & 0xC0, 0xC0);
      EXPECT_EQ(r.ack()[1] & 0x3F, p[1] & 0x3F);
    }
    if (o == Outcome::kDropped) {
      EXPECT_TRUE(r.ack().empty());
    }
  }
}

// ---------------------------------------------------------------------------
// I/O fragmentation.

TEST(IoFragmentation, TenBytePollCommandGolden) {
  const ByteVec poll = sequence(10);  // 01..0A
  ASSERT_EQ(io_fragment_count(poll.size()), 2u);
  std::array<std::uint8_t, 8> out{};
  auto n = io_fragment(poll, 0, out);
  ASSERT_TRUE(n.ok());
  // 00 first, count 0 | 01..07
  EXPECT_EQ(hex(Bytes(out.data(), *n)), "00 01 02 03 04 05 06 07");
  n = io_fragment(poll, 1, out);
  ASSERT_TRUE(n.ok());
  // 81 last, count 1 | 08 09 0A
  EXPECT_EQ(hex(Bytes(out.data(), *n)), "81 08 09 0A");
  EXPECT_EQ(io_fragment(poll, 2, out).error(), Errc::kOutOfRange);
  std::array<std::uint8_t, 7> small{};
  EXPECT_EQ(io_fragment(poll, 0, small).error(), Errc::kBufferTooSmall);
  EXPECT_TRUE(io_fragment(poll, 1, small).ok());  // 4 bytes fit

  IoReassembler r;
  const ByteVec f0 = {0x00, 1, 2, 3, 4, 5, 6, 7}, f1 = {0x81, 8, 9, 10};
  EXPECT_EQ(r.on_fragment(f0), IoOutcome::kIncomplete);
  EXPECT_EQ(r.on_fragment(f1), IoOutcome::kComplete);
  EXPECT_EQ(copy(r.message()), poll);
}

TEST(IoFragmentation, FragmentCounts) {
  EXPECT_EQ(io_fragment_count(0), 0u);
  EXPECT_EQ(io_fragment_count(1), 2u);
  EXPECT_EQ(io_fragment_count(7), 2u);
  EXPECT_EQ(io_fragment_count(8), 2u);
  EXPECT_EQ(io_fragment_count(14), 2u);
  EXPECT_EQ(io_fragment_count(15), 3u);
  EXPECT_EQ(io_fragment_count(500), 72u);
  std::array<std::uint8_t, 8> out{};
  EXPECT_EQ(io_fragment(Bytes(), 0, out).error(), Errc::kOutOfRange);
}

std::vector<ByteVec> io_frames(Bytes m) {
  std::vector<ByteVec> frames;
  for (std::size_t i = 0; i < io_fragment_count(m.size()); ++i) {
    std::array<std::uint8_t, 8> out{};
    auto n = io_fragment(m, i, out);
    EXPECT_TRUE(n.ok());
    if (n.ok()) frames.emplace_back(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(*n));
  }
  return frames;
}

TEST(IoFragmentation, RoundTripSizes1To100And500) {
  std::vector<std::size_t> sizes;
  for (std::size_t n = 1; n <= 100; ++n) sizes.push_back(n);
  sizes.push_back(500);
  for (std::size_t n : sizes) {
    const ByteVec m = sequence(n, 0x30);
    IoReassembler r;
    const auto frames = io_frames(m);
    ASSERT_EQ(frames.size(), io_fragment_count(n));
    for (std::size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i][0] & 0x3F, i % 64) << n;
      const IoOutcome o = r.on_fragment(frames[i]);
      EXPECT_EQ(o, i + 1 == frames.size() ? IoOutcome::kComplete : IoOutcome::kIncomplete)
          << n << " fragment " << i;
    }
    EXPECT_EQ(copy(r.message()), m) << n;
  }
}

TEST(IoFragmentation, OutOfOrderIsDetected) {
  const ByteVec m = sequence(30);  // 5 frames: first, 3 middles, last
  const auto f = io_frames(m);
  ASSERT_EQ(f.size(), 5u);
  {
    IoReassembler r;  // a middle skipped
    EXPECT_EQ(r.on_fragment(f[0]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[2]), IoOutcome::kOutOfOrder);
    EXPECT_EQ(r.on_fragment(f[3]), IoOutcome::kOutOfOrder);  // nothing in progress
    EXPECT_TRUE(r.message().empty());
  }
  {
    IoReassembler r;  // a middle twice
    EXPECT_EQ(r.on_fragment(f[0]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[1]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[1]), IoOutcome::kOutOfOrder);
  }
  {
    IoReassembler r;  // the last without the rest
    EXPECT_EQ(r.on_fragment(f[4]), IoOutcome::kOutOfOrder);
  }
  {
    IoReassembler r;  // a first with a count other than 0
    const ByteVec bad_first = {0x05, 1, 2};
    EXPECT_EQ(r.on_fragment(bad_first), IoOutcome::kOutOfOrder);
  }
  {
    IoReassembler r;  // a new first while one is in progress: old one discarded
    EXPECT_EQ(r.on_fragment(f[0]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[1]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[0]), IoOutcome::kOutOfOrder);
    for (std::size_t i = 1; i < 4; ++i) EXPECT_EQ(r.on_fragment(f[i]), IoOutcome::kIncomplete);
    EXPECT_EQ(r.on_fragment(f[4]), IoOutcome::kComplete);
    EXPECT_EQ(copy(r.message()), m);
  }
}

TEST(IoFragmentation, OverflowAndMalformed) {
  IoReassembler r(10);
  const auto f = io_frames(sequence(20));
  EXPECT_EQ(r.on_fragment(f[0]), IoOutcome::kIncomplete);
  EXPECT_EQ(r.on_fragment(f[1]), IoOutcome::kOverflow);
  EXPECT_TRUE(r.message().empty());
  EXPECT_EQ(r.on_fragment(f[2]), IoOutcome::kOutOfOrder);

  IoReassembler m;
  const ByteVec empty, nine = {0x00, 1, 2, 3, 4, 5, 6, 7, 8}, ack = {0xC0};
  EXPECT_EQ(m.on_fragment(empty), IoOutcome::kMalformed);
  EXPECT_EQ(m.on_fragment(nine), IoOutcome::kMalformed);
  EXPECT_EQ(m.on_fragment(ack), IoOutcome::kMalformed);
}

TEST(IoReassembler, GarbageKeepsInvariants) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 9);
  IoReassembler r(30);
  for (int i = 0; i < 50000; ++i) {
    ByteVec p(length(rng));
    for (auto& b : p) b = static_cast<std::uint8_t>(byte(rng));
    if (!p.empty() && (i % 2) == 0) p[0] &= 0x83;
    (void)r.on_fragment(p);
    EXPECT_LE(r.message().size(), 30u);
  }
}

}  // namespace
}  // namespace dnbridge::devicenet
