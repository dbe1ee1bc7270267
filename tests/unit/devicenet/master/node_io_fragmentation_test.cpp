// A node whose poll messages are over 8 bytes: the master fragments its poll
// commands and reassembles the responses (unacknowledged I/O fragmentation,
// bridge/PROTOCOL.md §5). The CDN127's formats fit one frame, so this runs
// against a small scripted Group 2 slave with 12 bytes consumed, 10 produced.
#include <gtest/gtest.h>

#include <deque>

#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/devicenet/wire/fragmentation.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

constexpr unsigned kSlave = 9;
MacId mac(unsigned v) { return MacId::from(v).value(); }

struct Recorder final : ScannerObserver {
  void on_poll_response(MacId, Bytes data, TimePoint) override {
    responses.emplace_back(data.begin(), data.end());
  }
  std::vector<std::vector<std::uint8_t>> responses;
};

struct Wire final : can::FrameSink {
  void send(const can::CanFrame& f, TimePoint) override { frames.push_back(f); }
  std::deque<can::CanFrame> frames;
};

// Answers the life-cycle requests of a generic Group 2 only slave and keeps
// its I/O in two buffers.
class ScriptedSlave {
 public:
  std::vector<can::CanFrame> on_frame(const can::CanFrame& f) {
    std::vector<can::CanFrame> out;
    auto id = decode_identifier(f.id);
    if (!id || id->group != MessageGroup::k2 || id->mac != mac(kSlave) || f.len == 0) {
      if (id && id->message_id == 5 && id->mac == mac(kSlave)) on_poll(f, out);
      return out;
    }
    const Bytes payload = f.payload();
    switch (static_cast<Group2Message>(id->message_id)) {
      case Group2Message::kUnconnectedExplicitRequest:
      case Group2Message::kMasterExplicitRequest: {
        auto request = decode_request(payload.subspan(1), BodyFormat::k8_8);
        if (!request) break;
        std::vector<std::uint8_t> body = answer(*request);
        std::vector<std::uint8_t> frame{payload[0]};
        frame.insert(frame.end(), body.begin(), body.end());
        out.push_back(
            can::CanFrame::make(group2_id(mac(kSlave), Group2Message::kSlaveExplicitResponse),
                                Bytes(frame))
                .value());
        break;
      }
      case Group2Message::kMasterIoPoll:
        on_poll(f, out);
        break;
      default:
        break;
    }
    return out;
  }

  std::vector<std::uint8_t> consumed;  // last complete poll command
  unsigned idle_polls = 0;
  std::vector<std::uint8_t> produced{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  bool scramble_next_response = false;

 private:
  std::vector<std::uint8_t> answer(const RequestMessage& r) {
    const auto ok = [&](std::vector<std::uint8_t> data) {
      data.insert(data.begin(), static_cast<std::uint8_t>(r.service | 0x80));
      return data;
    };
    if (r.service == 0x4B) return {0xCB, 0x00};
    if (r.service == 0x4C) return {0xCC};
    const auto key = (r.class_id << 16) | (r.instance_id << 8) | r.attribute.value_or(0);
    if (r.service == 0x0E) {
      switch (key) {
        case 0x010101:
          return ok({1, 0});  // vendor 1
        case 0x010102:
          return ok({12, 0});  // product type 12
        case 0x010103:
          return ok({34, 0});  // product code 34
        case 0x010104:
          return ok({2, 1});  // revision 2.1
        case 0x010106:
          return ok({4, 3, 2, 1});  // serial 0x01020304
        case 0x010107:
          return ok({2, 'I', 'O'});
        case 0x010108:
          return ok({3});
        case 0x050207:
          return ok({10, 0});  // produced size
        case 0x050208:
          return ok({12, 0});  // consumed size
        default:
          break;
      }
    }
    if (r.service == 0x10 && r.attribute == 9) return ok({r.data.begin(), r.data.end()});
    return {0x94, 0x14, 0xFF};
  }

  void on_poll(const can::CanFrame& f, std::vector<can::CanFrame>& out) {
    if (f.len == 0) {
      ++idle_polls;
    } else {
      switch (reassembler_.on_fragment(f.payload())) {
        case IoReassembler::Outcome::kComplete:
          consumed.assign(reassembler_.message().begin(), reassembler_.message().end());
          reassembler_.reset();
          break;
        case IoReassembler::Outcome::kIncomplete:
          return;
        default:
          reassembler_.reset();
          return;
      }
    }
    for (std::size_t i = 0; i < io_fragment_count(produced.size()); ++i) {
      can::CanFrame r;
      r.id = 0x3C0 + kSlave;
      r.len =
          static_cast<std::uint8_t>(io_fragment(Bytes(produced), i, MutableBytes(r.data)).value());
      out.push_back(r);
    }
    if (scramble_next_response) {
      std::swap(out[0], out[1]);  // last fragment first
      scramble_next_response = false;
    }
  }

  IoReassembler reassembler_{64};
};

class IoFragmentationTest : public ::testing::Test {
 protected:
  IoFragmentationTest() {
    ScannerConfig port;
    port.master_mac = mac(0);
    NodeConfig node;
    node.mac = mac(kSlave);
    node.name = "big";
    node.profile.identity = {1, 12, 34};
    node.profile.produced_size = 10;
    node.profile.consumed_size = 12;
    node.poll_period = milliseconds(20);
    node.expected_packet_rate = milliseconds(100);
    port.nodes.push_back(node);
    scanner_.emplace(port, wire_, events_, Logger());
  }

  // Runs the scanner and the scripted slave on an ideal bus until `until`.
  void run_until(TimePoint until) {
    for (;;) {
      while (!wire_.frames.empty()) {
        const can::CanFrame f = wire_.frames.front();
        wire_.frames.pop_front();
        if (f.id == 0x3C0 + kSlave) ++poll_response_frames_;
        if (f.id == group2_id(mac(kSlave), Group2Message::kMasterIoPoll)) ++poll_frames_;
        for (const auto& reply : slave_.on_frame(f)) wire_.send(reply, now_);
        if (f.id == 0x3C0 + kSlave ||
            f.id == group2_id(mac(kSlave), Group2Message::kSlaveExplicitResponse)) {
          scanner_->on_frame(f, now_);
        }
      }
      const TimePoint next = scanner_->next_deadline();
      if (next > until) break;
      now_ = std::max(now_, next);
      scanner_->on_timer(now_);
    }
    now_ = until;
  }

  TimePoint now_ = TimePoint{} + seconds(1);
  Wire wire_;
  Recorder events_;
  ScriptedSlave slave_;
  std::optional<Scanner> scanner_;
  unsigned poll_frames_ = 0;
  unsigned poll_response_frames_ = 0;
};

TEST_F(IoFragmentationTest, PollCommandsAndResponsesOverEightBytesAreFragmented) {
  scanner_->start(now_);
  run_until(now_ + seconds(5));
  const Node& node = *scanner_->node(mac(kSlave));
  ASSERT_EQ(node.state(), NodeState::kOnline) << node.reason();

  const std::vector<std::uint8_t> outputs{0xA0, 0xA1, 0xA2, 0xA3, 0xA4, 0xA5,
                                          0xA6, 0xA7, 0xA8, 0xA9, 0xAA, 0xAB};
  const unsigned frames_before = poll_frames_;
  const auto polls_before = node.counters().polls;
  ASSERT_TRUE(scanner_->set_outputs(mac(kSlave), Bytes(outputs), now_).ok());
  run_until(now_ + milliseconds(1));
  // 12 bytes: a first fragment of 7 and a last of 5.
  EXPECT_EQ(poll_frames_ - frames_before, 2u);
  EXPECT_EQ(node.counters().polls, polls_before + 1);
  EXPECT_EQ(slave_.consumed, outputs);
  ASSERT_FALSE(events_.responses.empty());
  EXPECT_EQ(events_.responses.back(), slave_.produced);

  run_until(now_ + seconds(1));
  EXPECT_EQ(node.counters().errors, 0u);
  EXPECT_EQ(node.counters().timeouts, 0u);
  EXPECT_EQ(node.counters().responses, node.counters().polls);
  EXPECT_EQ(poll_response_frames_, 2 * node.counters().responses);
}

TEST_F(IoFragmentationTest, ResponseFragmentsOutOfOrderAreCountedAndDropped) {
  scanner_->start(now_);
  run_until(now_ + seconds(5));
  const Node& node = *scanner_->node(mac(kSlave));
  ASSERT_EQ(node.state(), NodeState::kOnline);
  const auto taken = events_.responses.size();
  slave_.scramble_next_response = true;
  run_until(now_ + milliseconds(20));
  EXPECT_EQ(events_.responses.size(), taken);  // nothing taken from the scrambled one
  EXPECT_GE(node.counters().errors, 1u);
  EXPECT_EQ(node.last_error().kind, NodeError::Kind::kPollMalformed);
  run_until(now_ + milliseconds(100));
  EXPECT_GT(events_.responses.size(), taken);  // and the next ones are
  EXPECT_EQ(node.state(), NodeState::kOnline);
}

TEST_F(IoFragmentationTest, IdlePollIsOneEmptyFrame) {
  scanner_->start(now_);
  run_until(now_ + seconds(5));
  ASSERT_EQ(scanner_->node(mac(kSlave))->state(), NodeState::kOnline);
  const unsigned idle_before = slave_.idle_polls;
  const unsigned frames_before = poll_frames_;
  run_until(now_ + milliseconds(200));  // no outputs set: the node is idle
  EXPECT_EQ(slave_.idle_polls - idle_before, poll_frames_ - frames_before);
  EXPECT_GE(slave_.idle_polls - idle_before, 9u);
}

}  // namespace
}  // namespace dnbridge::devicenet
