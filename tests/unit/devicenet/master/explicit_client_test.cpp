#include "bridge/devicenet/master/explicit_client.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bridge/devicenet/wire/identifier.hpp"
#include "support/bytes.hpp"

namespace dnbridge::devicenet {
namespace {

using test::ByteVec;
using test::hex;
using Tag = ExplicitClient::Tag;

MacId mac(unsigned v) { return MacId::from(v).value(); }

// Master MAC 10 (0x0A), slave MAC 3 throughout.
constexpr std::uint32_t kConnectedId = 0x41C;    // G2 msg 4 to slave 3: 0x400 | 3 << 3 | 4
constexpr std::uint32_t kUnconnectedId = 0x41E;  // G2 msg 6 to slave 3: 0x400 | 3 << 3 | 6

class RecordingSink : public can::FrameSink {
 public:
  void send(const can::CanFrame& frame, TimePoint now) override {
    frames.push_back(frame);
    times.push_back(now);
  }
  // The frames sent so far as "ID: bytes", from index `from` on.
  std::vector<std::string> hex_from(std::size_t from) const {
    std::vector<std::string> out;
    for (std::size_t i = from; i < frames.size(); ++i) out.push_back(hex(frames[i]));
    return out;
  }
  std::string last() const { return frames.empty() ? std::string() : hex(frames.back()); }

  std::vector<can::CanFrame> frames;
  std::vector<TimePoint> times;
};

struct Recorded {
  Tag tag = 0;
  std::error_code error;
  std::uint8_t service = 0;
  cip::GeneralStatus general_status = cip::GeneralStatus::kSuccess;
  std::uint8_t additional_status = 0;
  std::string data;  // hex
  TimePoint at{};
};

class RecordingListener : public ExplicitClient::Listener {
 public:
  void on_explicit_result(Tag tag, const ExplicitResult& result, TimePoint now) override {
    results.push_back({tag, result.error, result.service, result.general_status,
                       result.additional_status, hex(result.data.view()), now});
    if (hook) hook(tag, result, now);
  }
  std::vector<Recorded> results;
  std::function<void(Tag, const ExplicitResult&, TimePoint)> hook;
};

RequestMessage get_single(std::uint16_t class_id, std::uint16_t instance, std::uint8_t attribute) {
  return {.service = 0x0E,
          .class_id = class_id,
          .instance_id = instance,
          .attribute = attribute,
          .data = {}};
}

class ExplicitClientTest : public ::testing::Test {
 protected:
  // Feeds one payload from the slave (Group 2 message 3, 0x41B).
  void answer(const ByteVec& payload) { client.on_frame(payload, now); }
  void advance(Duration d) { now += d; }
  // Runs the timer at every deadline up to `until`, as an event loop would.
  void run_until(TimePoint until) {
    for (int guard = 0; guard < 1000 && client.deadline() <= until; ++guard) {
      now = client.deadline();
      client.on_timer(now);
    }
    now = until;
  }
  Status submit_get(Tag tag, std::uint8_t attribute = 7) {
    return client.submit(tag, get_single(0x01, 0x01, attribute), false, now);
  }

  TimePoint now = TimePoint{} + seconds(100);
  RecordingSink sink;
  RecordingListener listener;
  ExplicitClient client{mac(10), mac(3), ExplicitClient::Config{}, sink, listener};
};

// ---------------------------------------------------------------------------
// Allocate, the golden exchange of bridge/PROTOCOL.md §3 (master 10, slave 3).

TEST_F(ExplicitClientTest, AllocateGoldenExchange) {
  EXPECT_EQ(client.deadline(), kNever);
  const ByteVec choice_and_allocator = {0x03, 0x0A};
  const RequestMessage allocate{.service = 0x4B,
                                .class_id = 0x03,
                                .instance_id = 0x01,
                                .attribute = std::nullopt,
                                .data = choice_and_allocator};
  ASSERT_TRUE(client.submit(1, allocate, /*unconnected=*/true, now).ok());

  // 41E: G2 message 6 to slave 3 | 4A header: Frag 0, XID 1 (the first
  // transaction toggles XID from 0), MAC 10 | 4B Allocate | 03 class DeviceNet
  // | 01 instance | 03 choice explicit + poll | 0A allocator MAC 10.
  // Identical to make_allocate_frame() except the XID bit.
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.last(), "41E: 4A 4B 03 01 03 0A");
  auto reference = make_allocate_frame(mac(3), mac(10), 0x03);
  ASSERT_TRUE(reference.ok());
  EXPECT_EQ(reference->id, sink.frames[0].id);
  EXPECT_EQ(reference->data[0] | 0x40, sink.frames[0].data[0]);
  EXPECT_TRUE(listener.results.empty());
  EXPECT_EQ(client.deadline(), now + milliseconds(2000));
  EXPECT_FALSE(client.idle());

  advance(milliseconds(3));
  // 41B answer: 4A header echoed (XID 1, MAC 10) | CB Allocate response |
  // 00 reserved 0, body format 0 (8/8).
  answer({0x4A, 0xCB, 0x00});
  ASSERT_EQ(listener.results.size(), 1u);
  const Recorded& r = listener.results[0];
  EXPECT_EQ(r.tag, 1u);
  EXPECT_FALSE(r.error) << r.error.message();
  EXPECT_EQ(r.service, 0x4B);
  EXPECT_EQ(r.data, "00");
  EXPECT_EQ(r.at, now);
  EXPECT_EQ(decode_allocate_response_data(ByteVec{0x00}).value(), BodyFormat::k8_8);

  EXPECT_TRUE(client.idle());
  EXPECT_EQ(client.deadline(), kNever);
  EXPECT_EQ(client.counters().requests, 1u);
  EXPECT_EQ(client.counters().responses, 1u);
  EXPECT_EQ(client.counters().unexpected_frames, 0u);
  EXPECT_EQ(sink.frames.size(), 1u);  // nothing else sent
}

TEST_F(ExplicitClientTest, AnswerWithWrongXidMacOrServiceIsUnexpectedAndIgnored) {
  const ByteVec data = {0x03, 0x0A};
  ASSERT_TRUE(client.submit(1, {0x4B, 0x03, 0x01, std::nullopt, data}, true, now).ok());

  answer({0x0A, 0xCB, 0x00});  // XID 0, as in bridge/PROTOCOL.md §3: not this transaction's
  EXPECT_EQ(client.counters().unexpected_frames, 1u);
  answer({0x4B, 0xCB, 0x00});  // MAC 11: another master's conversation
  EXPECT_EQ(client.counters().unexpected_frames, 2u);
  answer({0x4A, 0xCC});  // Release response: not the service asked
  EXPECT_EQ(client.counters().unexpected_frames, 3u);
  EXPECT_TRUE(listener.results.empty());
  EXPECT_FALSE(client.idle());

  answer({0x4A, 0xCB, 0x00});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);

  // The same answer again: nothing outstanding now.
  answer({0x4A, 0xCB, 0x00});
  EXPECT_EQ(client.counters().unexpected_frames, 4u);
  EXPECT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(client.counters().malformed_frames, 0u);
}

TEST_F(ExplicitClientTest, AnswerWithNoRequestOutstandingIsUnexpected) {
  answer({0x4A, 0x8E, 0x01});
  answer({0xCA, 0x00, 0x8E, 0x01});  // a response fragment
  answer({0xCA, 0xC0, 0x00});        // an ack
  EXPECT_EQ(client.counters().unexpected_frames, 3u);
  EXPECT_TRUE(listener.results.empty());
  EXPECT_TRUE(sink.frames.empty());  // no ack sent for a fragment nobody waits for
}

TEST_F(ExplicitClientTest, XidTogglesWithEveryTransaction) {
  for (Tag tag = 1; tag <= 3; ++tag) ASSERT_TRUE(submit_get(tag).ok());
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.last(), "41C: 4A 0E 01 01 07");  // XID 1
  answer({0x4A, 0x8E, 0x11});
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 07");  // XID 0
  answer({0x4A, 0x8E, 0x11});                     // the first answer repeated: old XID
  EXPECT_EQ(client.counters().unexpected_frames, 1u);
  answer({0x0A, 0x8E, 0x22});
  ASSERT_EQ(sink.frames.size(), 3u);
  EXPECT_EQ(sink.last(), "41C: 4A 0E 01 01 07");  // XID 1 again
  answer({0x4A, 0x8E, 0x33});
  ASSERT_EQ(listener.results.size(), 3u);
  EXPECT_EQ(listener.results[0].data, "11");
  EXPECT_EQ(listener.results[1].data, "22");
  EXPECT_EQ(listener.results[2].data, "33");
  EXPECT_EQ(client.counters().requests, 3u);
  EXPECT_EQ(client.counters().responses, 3u);
}

// ---------------------------------------------------------------------------

TEST_F(ExplicitClientTest, GetInBodyFormat8_16AfterSetBodyFormat) {
  client.set_body_format(BodyFormat::k8_16);
  EXPECT_EQ(client.body_format(), BodyFormat::k8_16);
  ASSERT_TRUE(client.submit(1, get_single(0x64, 0x0102, 0x03), false, now).ok());
  // 41C: G2 message 4 | 4A header | 0E Get_Attribute_Single | 64 class (8 bit)
  // | 02 01 instance 0x0102 (16 bit, little-endian) | 03 attribute.
  EXPECT_EQ(sink.last(), "41C: 4A 0E 64 02 01 03");
  answer({0x4A, 0x8E, 0x34, 0x12});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(listener.results[0].service, 0x0E);
  EXPECT_EQ(listener.results[0].data, "34 12");

  // Unconnected requests stay 8/8 whatever the connection's format.
  const ByteVec choice = {0x03};
  ASSERT_TRUE(client.submit(2, {0x4C, 0x03, 0x01, std::nullopt, choice}, true, now).ok());
  // 41E | 0A header: XID 0 (second transaction), MAC 10 | 4C Release | 03 | 01 | 03 choice
  EXPECT_EQ(sink.last(), "41E: 0A 4C 03 01 03");
}

TEST_F(ExplicitClientTest, RequestsThatDoNotFitAreRefusedWithoutResult) {
  // Class 0x100 does not fit 8/8.
  EXPECT_EQ(client.submit(1, get_single(0x100, 1, 1), false, now).error(), Errc::kOutOfRange);
  // Instance 0x100 does not fit an unconnected (always 8/8) request either.
  client.set_body_format(BodyFormat::k16_16);
  EXPECT_EQ(client.submit(2, get_single(0x03, 0x100, 1), true, now).error(), Errc::kOutOfRange);
  // Service data beyond the message buffer.
  const ByteVec huge(kMaxExplicitMessage, 0x55);
  const RequestMessage set{0x10, 0x64, 0x01, 0x03, huge};
  EXPECT_EQ(client.submit(3, set, false, now).error(), Errc::kOutOfRange);
  // A service with the response bit.
  EXPECT_EQ(client.submit(4, {0x8E, 1, 1, 7, {}}, false, now).error(), Errc::kOutOfRange);

  EXPECT_TRUE(sink.frames.empty());
  EXPECT_TRUE(listener.results.empty());
  EXPECT_TRUE(client.idle());
  EXPECT_EQ(client.counters().requests, 0u);
}

TEST_F(ExplicitClientTest, DeviceErrorCarriesGeneralAndAdditionalStatus) {
  ASSERT_TRUE(submit_get(1).ok());
  // 4A header | 94 error response | 0C object state conflict | 01 additional code
  answer({0x4A, 0x94, 0x0C, 0x01});
  ASSERT_EQ(listener.results.size(), 1u);
  const Recorded& r = listener.results[0];
  EXPECT_EQ(r.error, Errc::kDeviceError);
  EXPECT_EQ(r.service, 0x0E);
  EXPECT_EQ(r.general_status, cip::GeneralStatus::kObjectStateConflict);
  EXPECT_EQ(r.additional_status, 0x01);
  EXPECT_EQ(r.data, "");
  EXPECT_EQ(client.counters().device_errors, 1u);
  EXPECT_EQ(client.counters().responses, 0u);
  EXPECT_TRUE(client.idle());

  // Without the additional code: 0xFF (none).
  ASSERT_TRUE(submit_get(2).ok());
  answer({0x0A, 0x94, 0x08});
  ASSERT_EQ(listener.results.size(), 2u);
  EXPECT_EQ(listener.results[1].general_status, cip::GeneralStatus::kServiceNotSupported);
  EXPECT_EQ(listener.results[1].additional_status, cip::kNoAdditionalCode);
}

// ---------------------------------------------------------------------------
// Timeouts and the queue.

TEST_F(ExplicitClientTest, TimeoutEndsTheRequestAndStartsTheNext) {
  const TimePoint start = now;
  ASSERT_TRUE(submit_get(1).ok());
  ASSERT_TRUE(submit_get(2, 8).ok());
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(client.queued(), 2u);
  EXPECT_EQ(client.deadline(), start + milliseconds(2000));

  now = start + milliseconds(1999);
  client.on_timer(now);  // early: nothing happens
  EXPECT_TRUE(listener.results.empty());
  EXPECT_EQ(sink.frames.size(), 1u);

  now = start + milliseconds(2000);
  client.on_timer(now);
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].tag, 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kTimeout);
  EXPECT_EQ(listener.results[0].service, 0x0E);
  EXPECT_EQ(client.counters().timeouts, 1u);

  // The next one goes out at once, with the other XID and its own deadline.
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 08");
  EXPECT_EQ(sink.times.back(), now);
  EXPECT_EQ(client.deadline(), now + milliseconds(2000));

  answer({0x4A, 0x8E, 0x01});  // the late answer to the first: ignored
  EXPECT_EQ(client.counters().unexpected_frames, 1u);
  answer({0x0A, 0x8E, 0x02});
  ASSERT_EQ(listener.results.size(), 2u);
  EXPECT_EQ(listener.results[1].tag, 2u);
  EXPECT_EQ(listener.results[1].data, "02");
}

TEST_F(ExplicitClientTest, ConfiguredResponseTimeoutIsUsed) {
  ExplicitClient::Config config;
  config.response_timeout = milliseconds(250);
  ExplicitClient c(mac(10), mac(3), config, sink, listener);
  ASSERT_TRUE(c.submit(1, get_single(1, 1, 7), false, now).ok());
  EXPECT_EQ(c.deadline(), now + milliseconds(250));
  c.on_timer(now + milliseconds(250));
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kTimeout);
}

TEST_F(ExplicitClientTest, QueueFullIsBusyAndEveryAcceptedRequestGetsOneResult) {
  // One outstanding plus kQueueCapacity waiting.
  const Tag accepted = ExplicitClient::kQueueCapacity + 1;
  for (Tag tag = 1; tag <= accepted; ++tag) ASSERT_TRUE(submit_get(tag).ok()) << tag;
  EXPECT_EQ(client.queued(), accepted);
  EXPECT_EQ(submit_get(100).error(), Errc::kBusy);
  EXPECT_EQ(client.queued(), accepted);
  EXPECT_EQ(sink.frames.size(), 1u);

  bool xid = true;
  for (Tag tag = 1; tag <= accepted; ++tag) {
    answer({static_cast<std::uint8_t>(xid ? 0x4A : 0x0A), 0x8E, static_cast<std::uint8_t>(tag)});
    xid = !xid;
  }
  ASSERT_EQ(listener.results.size(), accepted);
  for (Tag tag = 1; tag <= accepted; ++tag) {
    EXPECT_EQ(listener.results[tag - 1].tag, tag);
    EXPECT_FALSE(listener.results[tag - 1].error);
  }
  EXPECT_TRUE(client.idle());
  // Room again.
  EXPECT_TRUE(submit_get(101).ok());
}

// ---------------------------------------------------------------------------
// Requests in fragments.

// Set_Attribute_Single class 0x64 instance 1 attribute 3 with 12 data bytes:
// a 16-byte message, sent as 6 + 6 + 4.
const ByteVec kTwelve = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C};
RequestMessage set_twelve() { return {0x10, 0x64, 0x01, 0x03, kTwelve}; }

TEST_F(ExplicitClientTest, RequestInFragmentsWithAcks) {
  const TimePoint start = now;
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  // CA header: Frag 1, XID 1, MAC 10 | 00 first, count 0 | 10 Set | 64 class |
  // 01 instance | 03 attribute | 01 02 data
  EXPECT_EQ(sink.hex_from(0), (std::vector<std::string>{"41C: CA 00 10 64 01 03 01 02"}));
  // Waiting for the ack: 1 s, no response timer yet.
  EXPECT_EQ(client.deadline(), start + seconds(1));

  advance(milliseconds(5));
  answer({0xCA, 0xC0, 0x00});  // slave ack of count 0, success
  // 41 middle, count 1 | 03 04 05 06 07 08
  EXPECT_EQ(sink.last(), "41C: CA 41 03 04 05 06 07 08");
  EXPECT_EQ(client.deadline(), now + seconds(1));

  advance(milliseconds(5));
  answer({0xCA, 0xC1, 0x00});
  // 82 last, count 2 | 09 0A 0B 0C
  EXPECT_EQ(sink.last(), "41C: CA 82 09 0A 0B 0C");

  advance(milliseconds(5));
  answer({0xCA, 0xC2, 0x00});
  EXPECT_EQ(sink.frames.size(), 3u);  // nothing more to send
  // The response timer starts when the last fragment is acknowledged.
  EXPECT_EQ(client.deadline(), now + milliseconds(2000));

  advance(milliseconds(5));
  answer({0x4A, 0x90});  // Set response, no data
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(listener.results[0].service, 0x10);
  EXPECT_EQ(client.counters().fragment_aborts, 0u);
  EXPECT_EQ(client.counters().unexpected_frames, 0u);
}

TEST_F(ExplicitClientTest, LostAckIsResentOnceAndTheTransferGoesOn) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  answer({0xCA, 0xC0, 0x00});
  ASSERT_EQ(sink.frames.size(), 2u);
  const std::string middle = sink.last();

  // The ack of the middle fragment is lost: after 1 s the same fragment again.
  advance(milliseconds(999));
  client.on_timer(now);
  EXPECT_EQ(sink.frames.size(), 2u);
  advance(milliseconds(1));
  client.on_timer(now);
  ASSERT_EQ(sink.frames.size(), 3u);
  EXPECT_EQ(sink.last(), middle);
  EXPECT_EQ(client.deadline(), now + seconds(1));
  EXPECT_TRUE(listener.results.empty());

  answer({0xCA, 0xC1, 0x00});  // the slave re-acks the repeat
  EXPECT_EQ(sink.last(), "41C: CA 82 09 0A 0B 0C");
  answer({0xCA, 0xC1, 0x00});  // a stale duplicate ack: ignored
  EXPECT_EQ(sink.frames.size(), 4u);
  answer({0xCA, 0xC2, 0x00});
  answer({0x4A, 0x90});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(client.counters().fragment_aborts, 0u);
}

TEST_F(ExplicitClientTest, TwiceLostAckAbortsAndTheNextRequestStarts) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  ASSERT_TRUE(submit_get(2).ok());
  const std::string first = sink.last();
  advance(seconds(1));
  client.on_timer(now);
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.last(), first);  // the one resend
  advance(seconds(1));
  client.on_timer(now);
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].tag, 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kAborted);
  EXPECT_EQ(listener.results[0].service, 0x10);
  EXPECT_EQ(client.counters().fragment_aborts, 1u);
  EXPECT_EQ(client.counters().timeouts, 0u);
  // The Get follows at once with XID 0.
  ASSERT_EQ(sink.frames.size(), 3u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 07");
  // A late ack of the abandoned transfer is not taken.
  answer({0xCA, 0xC0, 0x00});
  EXPECT_EQ(sink.frames.size(), 3u);
  EXPECT_EQ(client.counters().unexpected_frames, 1u);
}

TEST_F(ExplicitClientTest, NegativeAckAbortsTheRequest) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  answer({0xCA, 0xC0, 0x01});  // ack status 1: error / too much data
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_TRUE(listener.results[0].error);
  // Not a device error reply: no CIP status came with the refusal.
  EXPECT_EQ(listener.results[0].error, Errc::kAborted);
  EXPECT_EQ(client.counters().fragment_aborts, 1u);
  EXPECT_EQ(sink.frames.size(), 1u);
  EXPECT_TRUE(client.idle());
}

// Some devices never acknowledge a request's last fragment: they answer it.
// The response ends the transaction, and is counted.
TEST_F(ExplicitClientTest, ResponseWithoutTheAckOfTheLastFragmentEndsTheTransaction) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  answer({0xCA, 0xC0, 0x00});
  answer({0xCA, 0xC1, 0x00});
  ASSERT_EQ(sink.last(), "41C: CA 82 09 0A 0B 0C");  // the last fragment, count 2
  advance(milliseconds(300));
  answer({0x4A, 0x90});  // 4A: XID 1, MAC 10 | 90 Set response: no ack of count 2 came
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(listener.results[0].service, 0x10);
  EXPECT_EQ(client.counters().responses_before_final_ack, 1u);
  EXPECT_EQ(client.counters().unexpected_frames, 0u);
  EXPECT_TRUE(client.idle());
  // Nothing of the ended transfer is sent again.
  const auto sent = sink.frames.size();
  advance(seconds(3));
  client.on_timer(now);
  EXPECT_EQ(sink.frames.size(), sent);
}

// A response (here an error reply, in one frame) that comes before the
// request is through ends it too: the device does not want the rest.
TEST_F(ExplicitClientTest, ResponseBeforeTheRequestIsThroughEndsTheTransaction) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  // 4A | 94 error response | 15 too much data | FF no additional code
  answer({0x4A, 0x94, 0x15, 0xFF});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kDeviceError);
  EXPECT_EQ(client.counters().responses_before_final_ack, 1u);
  EXPECT_EQ(sink.frames.size(), 1u);  // the middle fragment is not sent
}

// A frame with this request's XID ends the transfer even if it turns out
// not to be the answer (here a reply to another service): the request then
// waits for its response timeout, and times out; it never hangs.
TEST_F(ExplicitClientTest, AnEarlyFrameThatIsNotTheAnswerLeavesTheRequestToTimeOut) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  answer({0x4A, 0x8E, 0x00});  // 8E: a Get response, not the Set's
  EXPECT_TRUE(listener.results.empty());
  EXPECT_EQ(client.deadline(), now + milliseconds(2000));
  advance(milliseconds(2000));
  client.on_timer(now);
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kTimeout);
  EXPECT_TRUE(client.idle());
}

// An answer with another XID is not this request's.
TEST_F(ExplicitClientTest, AnswerWithAnotherXidWhileSendingFragmentsIsUnexpected) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  answer({0x0A, 0x90});              // XID 0
  answer({0x8A, 0x00, 0x90, 0x00});  // a response fragment, XID 0
  EXPECT_EQ(client.counters().unexpected_frames, 2u);
  EXPECT_TRUE(listener.results.empty());
  EXPECT_EQ(sink.frames.size(), 1u);  // and no ack for that fragment
}

// ---------------------------------------------------------------------------
// Responses in fragments.

TEST_F(ExplicitClientTest, ResponseInFragmentsIsAckedAndReassembled) {
  // Identity product name, class 1 instance 1 attribute 7.
  ASSERT_TRUE(submit_get(1).ok());
  ASSERT_EQ(sink.last(), "41C: 4A 0E 01 01 07");
  const TimePoint start = now;

  // The answer 8E 06 "CDN127" is 8 bytes: two fragments.
  // CA header: Frag 1, XID 1, MAC 10 | 00 first, count 0 | 8E Get response |
  // 06 SHORT_STRING length | 43 44 4E 31 "CDN1"
  now = start + milliseconds(1500);
  answer({0xCA, 0x00, 0x8E, 0x06, 0x43, 0x44, 0x4E, 0x31});
  // Master's ack on G2 message 4: CA header | C0 ack, count 0 | 00 success
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.last(), "41C: CA C0 00");
  EXPECT_EQ(sink.frames.back().id, kConnectedId);
  EXPECT_TRUE(listener.results.empty());
  // A fragment restarts the response timer.
  EXPECT_EQ(client.deadline(), now + milliseconds(2000));

  // CA | 81 last, count 1 | 32 37 "27"
  now = start + milliseconds(3000);
  answer({0xCA, 0x81, 0x32, 0x37});
  ASSERT_EQ(sink.frames.size(), 3u);
  EXPECT_EQ(sink.last(), "41C: CA C1 00");
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(listener.results[0].service, 0x0E);
  EXPECT_EQ(listener.results[0].data, "06 43 44 4E 31 32 37");
  EXPECT_EQ(client.counters().responses, 1u);
  EXPECT_EQ(client.counters().malformed_frames, 0u);
  EXPECT_TRUE(client.idle());
}

TEST_F(ExplicitClientTest, ResponseFragmentsKeepTheTransactionAlive) {
  ASSERT_TRUE(submit_get(1).ok());
  const TimePoint start = now;
  run_until(start + milliseconds(1900));
  answer({0xCA, 0x00, 0x8E, 0x0C, 0x41, 0x42, 0x43, 0x44});
  run_until(start + milliseconds(3800));  // past the first deadline
  answer({0xCA, 0x41, 0x45, 0x46, 0x47, 0x48, 0x49, 0x4A});
  run_until(start + milliseconds(5700));
  EXPECT_TRUE(listener.results.empty());
  EXPECT_EQ(client.counters().timeouts, 0u);
  // The last fragment never comes: timeout 2 s after the middle one.
  run_until(start + milliseconds(5799));
  EXPECT_TRUE(listener.results.empty());
  run_until(start + milliseconds(5800));
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kTimeout);
  EXPECT_EQ(listener.results[0].at, start + milliseconds(5800));
}

TEST_F(ExplicitClientTest, RepeatedResponseFragmentIsReAckedNotAppended) {
  ASSERT_TRUE(submit_get(1).ok());
  answer({0xCA, 0x00, 0x8E, 0x0A, 0x01, 0x02, 0x03, 0x04});
  answer({0xCA, 0x00, 0x8E, 0x0A, 0x01, 0x02, 0x03, 0x04});  // our ack was lost
  answer({0xCA, 0x41, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A});
  answer({0xCA, 0x41, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A});  // and again
  answer({0xCA, 0x82, 0x0B});
  EXPECT_EQ(sink.hex_from(1),
            (std::vector<std::string>{"41C: CA C0 00", "41C: CA C0 00", "41C: CA C1 00",
                                      "41C: CA C1 00", "41C: CA C2 00"}));
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].data, "0A 01 02 03 04 05 06 07 08 09 0A 0B");
  EXPECT_EQ(client.counters().malformed_frames, 0u);
  EXPECT_EQ(client.counters().unexpected_frames, 0u);
}

TEST_F(ExplicitClientTest, FinalResponseFragmentRepeatedAfterCompletionIsReAcked) {
  ASSERT_TRUE(submit_get(1).ok());
  ASSERT_TRUE(submit_get(2, 8).ok());
  answer({0xCA, 0x00, 0x8E, 0x06, 0x43, 0x44, 0x4E, 0x31});
  answer({0xCA, 0x81, 0x32, 0x37});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 08");  // the next request is out
  const std::size_t sent = sink.frames.size();

  // The slave missed our ack of its last fragment and sends it again after
  // its 1 s ack timeout: re-acked so that it does not abort a response that
  // arrived (bridge/PROTOCOL.md §5), and not taken as an answer to request 2.
  advance(seconds(1));
  answer({0xCA, 0x81, 0x32, 0x37});
  ASSERT_EQ(sink.frames.size(), sent + 1);
  EXPECT_EQ(sink.last(), "41C: CA C1 00");
  EXPECT_EQ(listener.results.size(), 1u);
  // Any other fragment of the old XID is still not ours and not acked.
  answer({0xCA, 0x41, 0x32, 0x37});
  answer({0xCA, 0x00, 0x8E, 0x06, 0x43, 0x44, 0x4E, 0x31});
  EXPECT_EQ(sink.frames.size(), sent + 1);
  EXPECT_EQ(client.counters().unexpected_frames, 2u);

  answer({0x0A, 0x8E, 0x02});
  ASSERT_EQ(listener.results.size(), 2u);
  EXPECT_EQ(listener.results[1].data, "02");

  // Idle, the same repeat is re-acked too.
  answer({0xCA, 0x81, 0x32, 0x37});
  EXPECT_EQ(sink.last(), "41C: CA C1 00");
  EXPECT_EQ(sink.frames.size(), sent + 2);
  EXPECT_EQ(listener.results.size(), 2u);

  // Once a transaction with that XID is under way again, the frame is taken as
  // one of its own: a last fragment with no first, dropped and not acked.
  ASSERT_TRUE(submit_get(3).ok());
  EXPECT_EQ(sink.last(), "41C: 4A 0E 01 01 07");
  const std::uint64_t malformed = client.counters().malformed_frames;
  answer({0xCA, 0x81, 0x32, 0x37});
  EXPECT_EQ(sink.frames.size(), sent + 3);
  EXPECT_EQ(client.counters().malformed_frames, malformed + 1);
  EXPECT_EQ(listener.results.size(), 2u);
}

TEST_F(ExplicitClientTest, ResponseFragmentWithOldXidIsNotAcked) {
  ASSERT_TRUE(submit_get(1).ok());
  answer({0x8A, 0x00, 0x8E, 0x06, 0x43, 0x44, 0x4E, 0x31});  // XID 0
  EXPECT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(client.counters().unexpected_frames, 1u);
}

TEST_F(ExplicitClientTest, ErrorResponseInFragments) {
  ASSERT_TRUE(submit_get(1).ok());
  answer({0xCA, 0x00, 0x94, 0x14});
  answer({0xCA, 0x81, 0x05});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kDeviceError);
  EXPECT_EQ(listener.results[0].general_status, cip::GeneralStatus::kAttributeNotSupported);
  EXPECT_EQ(listener.results[0].additional_status, 0x05);
}

TEST_F(ExplicitClientTest, OversizedResponseIsRefusedWithErrorAck) {
  ASSERT_TRUE(submit_get(1).ok());
  // 6 bytes a fragment: the 86th would take the message to 516 > 512 bytes.
  // Counts wrap modulo 64 on the way.
  ByteVec fragment = {0xCA, 0x00, 0x8E, 0, 0, 0, 0, 0};
  answer(fragment);
  for (unsigned i = 1; i < 85; ++i) {
    fragment = {0xCA, static_cast<std::uint8_t>(0x40 | (i & 0x3F)), 1, 2, 3, 4, 5, 6};
    answer(fragment);
  }
  ASSERT_EQ(sink.frames.size(), 86u);                     // request + 85 acks
  EXPECT_EQ(sink.hex_from(64).front(), "41C: CA FF 00");  // count 63
  EXPECT_EQ(sink.hex_from(65).front(), "41C: CA C0 00");  // count 0 after the wrap
  EXPECT_TRUE(listener.results.empty());

  answer({0xCA, 0x40 | 21, 1, 2, 3, 4, 5, 6});  // 85 & 63 = 21
  // D5: ack count 21 | 01 status error
  EXPECT_EQ(sink.last(), "41C: CA D5 01");
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(listener.results[0].error, Errc::kOutOfRange);
  EXPECT_TRUE(client.idle());
}

// ---------------------------------------------------------------------------
// Garbage.

TEST_F(ExplicitClientTest, TruncatedFragmentsAreMalformedAndKeepTheTransaction) {
  answer({});  // empty, idle
  EXPECT_EQ(client.counters().malformed_frames, 1u);
  ASSERT_TRUE(submit_get(1).ok());
  answer({});
  answer({0xCA});              // Frag set, no fragment byte
  answer({0xCA, 0x41, 0x01});  // a middle fragment with no first
  answer({0xCA, 0x05, 0x01});  // a first fragment with count 5
  EXPECT_EQ(client.counters().malformed_frames, 5u);
  EXPECT_EQ(sink.frames.size(), 1u);  // none of them acked
  EXPECT_TRUE(listener.results.empty());
  answer({0x4A, 0x8E, 0x07});
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_FALSE(listener.results[0].error);
}

TEST_F(ExplicitClientTest, UnparsableAnswerEndsTheTransactionMalformed) {
  const std::vector<ByteVec> answers = {
      {0x4A},              // header only
      {0x4A, 0x94},        // error response without its general status
      {0x4A, 0x94, 0x00},  // error response reporting success
      {0x4A, 0x0E, 0x01},  // a request (R/R clear)
  };
  bool xid = true;
  for (std::size_t i = 0; i < answers.size(); ++i) {
    ByteVec a = answers[i];
    a[0] = static_cast<std::uint8_t>(xid ? 0x4A : 0x0A);
    xid = !xid;
    ASSERT_TRUE(submit_get(static_cast<Tag>(i)).ok());
    answer(a);
    ASSERT_EQ(listener.results.size(), i + 1) << hex(a);
    EXPECT_EQ(listener.results[i].error, Errc::kMalformed) << hex(a);
    EXPECT_EQ(client.counters().malformed_frames, i + 1);
  }
}

TEST_F(ExplicitClientTest, RandomFramesNeverBreakTheClient) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> length(0, 8);
  Tag next_tag = 1;
  std::size_t submitted = 0;
  for (int i = 0; i < 20000; ++i) {
    if (client.queued() < 3) {
      const bool long_one = (i % 3) == 0;
      const Status s =
          long_one ? client.submit(next_tag, set_twelve(), false, now) : submit_get(next_tag);
      ASSERT_TRUE(s.ok());
      ++next_tag;
      ++submitted;
    }
    ByteVec payload(static_cast<std::size_t>(length(rng)));
    for (auto& b : payload) b = static_cast<std::uint8_t>(byte(rng));
    // Bias towards this client's MAC so that the deeper paths are reached.
    if (!payload.empty() && (i % 2) == 0) {
      payload[0] = static_cast<std::uint8_t>((payload[0] & 0xC0) | 10);
    }
    client.on_frame(payload, now);
    advance(milliseconds(7));
    if (now >= client.deadline()) client.on_timer(now);
    ASSERT_TRUE(client.deadline() > now);
    for (const auto& f : sink.frames) {
      ASSERT_LE(f.len, 8);
      ASSERT_TRUE(f.id == kConnectedId || f.id == kUnconnectedId) << hex(f);
    }
    sink.frames.clear();
  }
  client.cancel_all(Errc::kStopped, now);
  // Exactly one result per accepted request, in submission order.
  ASSERT_EQ(listener.results.size(), submitted);
  for (std::size_t k = 0; k < submitted; ++k) EXPECT_EQ(listener.results[k].tag, k + 1);
  const auto& c = client.counters();
  EXPECT_GT(c.malformed_frames + c.unexpected_frames, 0u);
}

// ---------------------------------------------------------------------------
// Re-entrancy and cancellation.

TEST_F(ExplicitClientTest, SubmitFromTheListenerStartsAfterTheCurrentCompletes) {
  std::size_t frames_in_callback = 0;
  std::size_t queued_in_callback = 0;
  listener.hook = [&](Tag tag, const ExplicitResult&, TimePoint t) {
    if (tag != 1) return;
    EXPECT_TRUE(client.submit(2, get_single(1, 1, 8), false, t).ok());
    frames_in_callback = sink.frames.size();
    queued_in_callback = client.queued();
  };
  ASSERT_TRUE(submit_get(1).ok());
  answer({0x4A, 0x8E, 0x01});
  // Inside the callback the new request waited...
  EXPECT_EQ(frames_in_callback, 1u);
  EXPECT_EQ(queued_in_callback, 1u);
  // ... and went out once the callback returned.
  ASSERT_EQ(sink.frames.size(), 2u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 08");
  EXPECT_FALSE(client.idle());
  answer({0x0A, 0x8E, 0x02});
  ASSERT_EQ(listener.results.size(), 2u);
  EXPECT_EQ(listener.results[1].tag, 2u);
}

TEST_F(ExplicitClientTest, SubmitFromTheListenerQueuesBehindWaitingRequests) {
  listener.hook = [&](Tag tag, const ExplicitResult&, TimePoint t) {
    if (tag == 1) {
      EXPECT_TRUE(client.submit(3, get_single(1, 1, 9), false, t).ok());
    }
  };
  ASSERT_TRUE(submit_get(1).ok());
  ASSERT_TRUE(submit_get(2, 8).ok());
  run_until(now + seconds(2));  // tag 1 times out
  ASSERT_EQ(listener.results.size(), 1u);
  EXPECT_EQ(sink.last(), "41C: 0A 0E 01 01 08");  // tag 2 first
  answer({0x0A, 0x8E, 0x02});
  EXPECT_EQ(sink.last(), "41C: 4A 0E 01 01 09");  // then tag 3
  answer({0x4A, 0x8E, 0x03});
  ASSERT_EQ(listener.results.size(), 3u);
  EXPECT_EQ(listener.results[1].tag, 2u);
  EXPECT_EQ(listener.results[2].tag, 3u);
}

TEST_F(ExplicitClientTest, CancelAllEndsEveryRequestExactlyOnce) {
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());  // outstanding, fragmenting
  for (Tag tag = 2; tag <= 4; ++tag) ASSERT_TRUE(submit_get(tag).ok());
  std::vector<Status> resubmits;
  listener.hook = [&](Tag, const ExplicitResult&, TimePoint) {
    // Refused while cancelling (bounded, so that a client which took them
    // fails this test rather than looping).
    if (resubmits.size() < 8) resubmits.push_back(submit_get(99));
  };
  const std::size_t frames_before = sink.frames.size();
  client.cancel_all(Errc::kStopped, now);
  ASSERT_EQ(listener.results.size(), 4u);
  for (Tag tag = 1; tag <= 4; ++tag) {
    EXPECT_EQ(listener.results[tag - 1].tag, tag);
    EXPECT_EQ(listener.results[tag - 1].error, Errc::kStopped);
  }
  EXPECT_EQ(listener.results[0].service, 0x10);
  EXPECT_EQ(listener.results[1].service, 0x0E);
  ASSERT_EQ(resubmits.size(), 4u);
  for (const Status& s : resubmits) EXPECT_EQ(s.error(), Errc::kStopped);
  EXPECT_EQ(sink.frames.size(), frames_before);  // nothing sent while cancelling
  EXPECT_TRUE(client.idle());
  EXPECT_EQ(client.deadline(), kNever);

  // Nothing comes back later.
  listener.hook = nullptr;
  answer({0xCA, 0xC0, 0x00});
  client.on_timer(now + seconds(10));
  client.cancel_all(Errc::kStopped, now);
  EXPECT_EQ(listener.results.size(), 4u);

  // The client works afterwards.
  ASSERT_TRUE(submit_get(5).ok());
  EXPECT_EQ(sink.frames.size(), frames_before + 1);
}

TEST_F(ExplicitClientTest, CancelAllPassesTheReason) {
  ASSERT_TRUE(submit_get(1).ok());
  ASSERT_TRUE(submit_get(2).ok());
  client.cancel_all(Errc::kNotConnected, now);
  ASSERT_EQ(listener.results.size(), 2u);
  EXPECT_EQ(listener.results[0].error, Errc::kNotConnected);
  EXPECT_EQ(listener.results[1].error, Errc::kNotConnected);
}

TEST_F(ExplicitClientTest, CancelAllFromTheListener) {
  for (Tag tag = 1; tag <= 3; ++tag) ASSERT_TRUE(submit_get(tag).ok());
  listener.hook = [&](Tag tag, const ExplicitResult&, TimePoint t) {
    if (tag == 1) client.cancel_all(Errc::kStopped, t);
  };
  answer({0x4A, 0x8E, 0x01});
  ASSERT_EQ(listener.results.size(), 3u);
  EXPECT_FALSE(listener.results[0].error);
  EXPECT_EQ(listener.results[1].error, Errc::kStopped);
  EXPECT_EQ(listener.results[2].error, Errc::kStopped);
  EXPECT_EQ(sink.frames.size(), 1u);
  EXPECT_TRUE(client.idle());
}

// ---------------------------------------------------------------------------
// Deadlines.

TEST_F(ExplicitClientTest, DeadlineIsNeverInThePastAfterOnTimer) {
  EXPECT_EQ(client.deadline(), kNever);
  client.on_timer(now);  // idle: harmless
  EXPECT_EQ(client.deadline(), kNever);
  EXPECT_TRUE(sink.frames.empty());

  // A mix of fragmented and plain requests, nobody answering.
  ASSERT_TRUE(client.submit(1, set_twelve(), false, now).ok());
  ASSERT_TRUE(submit_get(2).ok());
  ASSERT_TRUE(client.submit(3, set_twelve(), false, now).ok());
  int wakeups = 0;
  while (client.deadline() != kNever) {
    ASSERT_LT(++wakeups, 20) << "timer loop does not settle";
    now = client.deadline();
    client.on_timer(now);
    EXPECT_GT(client.deadline(), now);
  }
  // Each fragmented one: first send, one resend, abort (2 wakeups); the Get: one.
  EXPECT_EQ(wakeups, 5);
  ASSERT_EQ(listener.results.size(), 3u);
  EXPECT_EQ(listener.results[0].error, Errc::kAborted);
  EXPECT_EQ(listener.results[1].error, Errc::kTimeout);
  EXPECT_EQ(listener.results[2].error, Errc::kAborted);
  EXPECT_TRUE(client.idle());

  // Called late, the timer still leaves a future deadline.
  ASSERT_TRUE(client.submit(4, set_twelve(), false, now).ok());
  now += seconds(30);
  client.on_timer(now);
  EXPECT_GT(client.deadline(), now);
}

}  // namespace
}  // namespace dnbridge::devicenet
