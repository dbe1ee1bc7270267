// The poll connection on its own: its slots, the polls it sends for changed
// outputs and their minimum gap, idle polls, responses whole and in
// fragments, late and wrong-sized ones, and the strays of the idle poll
// before a Release.
#include "bridge/devicenet/master/poll_connection.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "bridge/devicenet/wire/fragmentation.hpp"
#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

constexpr unsigned kNodeMac = 12;
const TimePoint kT0 = TimePoint{} + seconds(100);

struct Wire final : can::FrameSink {
  void send(const can::CanFrame& f, TimePoint at) override {
    frames.push_back(f);
    times.push_back(at);
  }
  std::vector<can::CanFrame> frames;
  std::vector<TimePoint> times;
};

struct Answers final : PollConnection::Listener {
  void on_poll_answer(Bytes inputs, bool late, TimePoint) override {
    answers.emplace_back(inputs.begin(), inputs.end());
    lates.push_back(late);
  }
  void on_bad_poll_answer(NodeError::Kind kind, std::uint32_t got, TimePoint) override {
    bad.push_back(kind);
    bad_sizes.push_back(got);
  }
  std::vector<std::vector<std::uint8_t>> answers;
  std::vector<bool> lates;
  std::vector<NodeError::Kind> bad;
  std::vector<std::uint32_t> bad_sizes;
};

NodeConfig node_config(std::size_t consumed, std::size_t produced) {
  NodeConfig c;
  c.mac = MacId::from(kNodeMac).value();
  c.profile.consumed_size = consumed;
  c.profile.produced_size = produced;
  c.poll_period = milliseconds(10);
  c.immediate_poll_min_gap = milliseconds(4);
  return c;
}

class PollConnectionTest : public ::testing::Test {
 protected:
  explicit PollConnectionTest(std::size_t consumed = 4, std::size_t produced = 6)
      : config_(node_config(consumed, produced)) {
    port_.poll_response_timeout = milliseconds(50);
  }

  NodeConfig config_;
  ScannerConfig port_;
  Wire wire_;
  NodeCounters counters_;
  Answers answers_;
  PollConnection poll_{config_, port_, wire_, counters_, answers_};

  std::vector<std::uint8_t> last_payload() const {
    const Bytes p = wire_.frames.back().payload();
    return {p.begin(), p.end()};
  }
};

TEST_F(PollConnectionTest, SlotsFollowThePhaseAndAreNotDoubledWhileAPollIsOutstanding) {
  poll_.set_phase(kT0 + milliseconds(3));
  poll_.start(kT0 + milliseconds(5));
  EXPECT_EQ(poll_.next_slot(), kT0 + milliseconds(13));

  poll_.on_timer(kT0 + milliseconds(13));
  ASSERT_EQ(wire_.frames.size(), 1u);
  EXPECT_EQ(wire_.frames[0].id, group2_id(config_.mac, Group2Message::kMasterIoPoll));
  EXPECT_EQ(wire_.frames[0].len, 0) << "no outputs set yet: an idle poll";
  EXPECT_EQ(poll_.next_slot(), kT0 + milliseconds(23));
  // The response deadline is the shorter of the port's timeout and the period.
  EXPECT_EQ(poll_.response_deadline(), kT0 + milliseconds(23));

  // The next slot while the first poll waits: nothing sent, the slot moves on.
  poll_.on_timer(kT0 + milliseconds(23));
  EXPECT_EQ(wire_.frames.size(), 1u);
  EXPECT_EQ(poll_.next_slot(), kT0 + milliseconds(33));
}

TEST_F(PollConnectionTest, AnUnansweredPollMakesTheNextARetry) {
  poll_.start(kT0);
  poll_.send(kT0);
  poll_.give_up();
  EXPECT_FALSE(poll_.outstanding());
  EXPECT_EQ(poll_.response_deadline(), kNever);
  poll_.send(kT0 + milliseconds(10));
  EXPECT_EQ(counters_.polls, 2u);
  EXPECT_EQ(counters_.retries, 1u);
  EXPECT_EQ(counters_.idle_polls, 2u);
}

TEST_F(PollConnectionTest, ChangedOutputsWithinTheMinimumGapGoOutTogetherAtItsEnd) {
  poll_.set_phase(kT0 + milliseconds(7));
  poll_.start(kT0);
  const std::vector<std::uint8_t> a{1, 2, 3, 4};
  const std::vector<std::uint8_t> b{5, 6, 7, 8};
  ASSERT_TRUE(poll_.set_outputs(Bytes(a)));
  poll_.send_for_change(kT0 + milliseconds(1));
  ASSERT_EQ(wire_.frames.size(), 1u);
  EXPECT_EQ(last_payload(), a);
  poll_.drop_outstanding();

  ASSERT_TRUE(poll_.set_outputs(Bytes(b)));
  EXPECT_FALSE(poll_.set_outputs(Bytes(b))) << "the same outputs again are no change";
  poll_.send_for_change(kT0 + milliseconds(2));
  EXPECT_EQ(wire_.frames.size(), 1u) << "within the gap: held back";
  EXPECT_TRUE(poll_.dirty());
  EXPECT_EQ(poll_.timers_deadline(), kT0 + milliseconds(5));

  poll_.on_timer(kT0 + milliseconds(5));
  ASSERT_EQ(wire_.frames.size(), 2u);
  EXPECT_EQ(wire_.times[1], kT0 + milliseconds(5));
  EXPECT_EQ(last_payload(), b);
  EXPECT_FALSE(poll_.dirty());
}

TEST_F(PollConnectionTest, ASlotBeforeTheGapsEndCarriesTheHeldBackChange) {
  poll_.set_phase(kT0 + milliseconds(3));
  poll_.start(kT0);
  const std::vector<std::uint8_t> a{1, 0, 0, 0};
  const std::vector<std::uint8_t> b{2, 0, 0, 0};
  poll_.set_outputs(Bytes(a));
  poll_.send_for_change(kT0 + milliseconds(1));
  poll_.drop_outstanding();
  poll_.set_outputs(Bytes(b));
  poll_.send_for_change(kT0 + milliseconds(2));  // held back to 5 ms
  poll_.on_timer(kT0 + milliseconds(3));         // the slot comes first
  ASSERT_EQ(wire_.frames.size(), 2u);
  EXPECT_EQ(last_payload(), b);
  EXPECT_EQ(poll_.timers_deadline(), kT0 + milliseconds(13))
      << "the held-back poll went with the slot: the next slot is next";
}

TEST_F(PollConnectionTest, AnAnswerRecordsWhatTheDeviceApplied) {
  poll_.start(kT0);
  const std::vector<std::uint8_t> out{9, 8, 7, 6};
  poll_.set_outputs(Bytes(out));
  poll_.send(kT0);
  const std::vector<std::uint8_t> in{1, 2, 3, 4, 5, 6};
  poll_.on_response(Bytes(in), kT0 + milliseconds(2));
  ASSERT_EQ(answers_.answers.size(), 1u);
  EXPECT_EQ(answers_.answers[0], in);
  EXPECT_FALSE(answers_.lates[0]);
  EXPECT_FALSE(poll_.outstanding());
  EXPECT_FALSE(poll_.applied_idle());
  EXPECT_EQ(
      std::vector<std::uint8_t>(poll_.applied_outputs().begin(), poll_.applied_outputs().end()),
      out);
  EXPECT_EQ(poll_.silence(kT0 + milliseconds(12)), milliseconds(10));
  EXPECT_EQ(counters_.responses, 1u);

  // One that comes after its poll was given up is still taken, as late.
  poll_.send(kT0 + milliseconds(10));
  poll_.give_up();
  poll_.on_response(Bytes(in), kT0 + milliseconds(70));
  ASSERT_EQ(answers_.lates.size(), 2u);
  EXPECT_TRUE(answers_.lates[1]);
}

TEST_F(PollConnectionTest, AnIdlePollMayBeAnsweredEmptyAndOtherSizesAreBad) {
  poll_.start(kT0);
  poll_.send(kT0);  // idle
  poll_.on_response(Bytes(), kT0 + milliseconds(1));
  ASSERT_EQ(answers_.answers.size(), 1u);
  EXPECT_TRUE(answers_.answers[0].empty());
  EXPECT_EQ(counters_.idle_empty_responses, 1u);

  const std::vector<std::uint8_t> short_one{1, 2, 3};
  poll_.send(kT0 + milliseconds(10));
  poll_.on_response(Bytes(short_one), kT0 + milliseconds(11));
  ASSERT_EQ(answers_.bad.size(), 1u);
  EXPECT_EQ(answers_.bad[0], NodeError::Kind::kPollLength);
  EXPECT_EQ(answers_.bad_sizes[0], 3u);
  EXPECT_TRUE(poll_.outstanding()) << "the node decides what a bad answer ends";
  EXPECT_EQ(poll_.count_error(), 1u);
  EXPECT_EQ(poll_.count_error(), 2u);
  poll_.on_response(Bytes(), kT0 + milliseconds(12));
  EXPECT_EQ(poll_.count_error(), 1u) << "an answer ends the run of bad ones";
}

TEST_F(PollConnectionTest, AConnectionThatConsumesNothingAlwaysPollsEmpty) {
  config_.profile.consumed_size = 0;
  EXPECT_TRUE(poll_.set_idle(false));
  EXPECT_FALSE(poll_.set_idle(false));
  poll_.send(kT0);
  EXPECT_EQ(wire_.frames.back().len, 0);
  EXPECT_EQ(counters_.idle_polls, 1u);
}

TEST_F(PollConnectionTest, TheIdlePollBeforeAReleaseLeavesItsAnswersAsStrays) {
  poll_.start(kT0);
  const std::vector<std::uint8_t> out{1, 1, 1, 1};
  poll_.set_outputs(Bytes(out));
  poll_.send(kT0);  // outstanding
  poll_.send_idle_before_release(kT0 + milliseconds(1));
  EXPECT_EQ(wire_.frames.back().len, 0) << "idle, whatever the outputs";
  EXPECT_FALSE(poll_.idle()) << "the outputs in force are kept";
  EXPECT_FALSE(poll_.outstanding());
  EXPECT_EQ(poll_.response_deadline(), kNever);
  ASSERT_TRUE(poll_.strays_expected());
  const std::vector<std::uint8_t> in(6, 0);
  poll_.take_stray(Bytes(in));
  EXPECT_TRUE(poll_.strays_expected()) << "two: the poll outstanding's answer and the idle one's";
  poll_.take_stray(Bytes());
  EXPECT_FALSE(poll_.strays_expected());
}

class FragmentedPollConnectionTest : public PollConnectionTest {
 protected:
  FragmentedPollConnectionTest() : PollConnectionTest(12, 10) {}
};

std::vector<can::CanFrame> fragments_of(const std::vector<std::uint8_t>& message) {
  std::vector<can::CanFrame> out;
  for (std::size_t i = 0; i < io_fragment_count(message.size()); ++i) {
    can::CanFrame f;
    f.len = static_cast<std::uint8_t>(io_fragment(Bytes(message), i, MutableBytes(f.data)).value());
    out.push_back(f);
  }
  return out;
}

TEST_F(FragmentedPollConnectionTest, OutputsOverEightBytesGoInFragmentsAndAnswersAreReassembled) {
  poll_.start(kT0);
  const std::vector<std::uint8_t> out{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  poll_.set_outputs(Bytes(out));
  poll_.send(kT0);
  ASSERT_EQ(wire_.frames.size(), fragments_of(out).size());
  IoReassembler device(kMaxIoMessageSize);
  for (const auto& f : wire_.frames) device.on_fragment(f.payload());
  EXPECT_EQ(std::vector<std::uint8_t>(device.message().begin(), device.message().end()), out);

  const std::vector<std::uint8_t> in{10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
  const auto frames = fragments_of(in);
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    poll_.on_response(frames[i].payload(), kT0 + milliseconds(1));
    EXPECT_TRUE(answers_.answers.empty());
  }
  poll_.on_response(frames.back().payload(), kT0 + milliseconds(1));
  ASSERT_EQ(answers_.answers.size(), 1u);
  EXPECT_EQ(answers_.answers[0], in);

  // The last fragment without the first: out of order, the message discarded.
  poll_.send(kT0 + milliseconds(10));
  poll_.on_response(frames.back().payload(), kT0 + milliseconds(11));
  ASSERT_EQ(answers_.bad.size(), 1u);
  EXPECT_EQ(answers_.bad[0], NodeError::Kind::kPollMalformed);
  EXPECT_EQ(answers_.bad_sizes[0], frames.back().len);
}

TEST_F(FragmentedPollConnectionTest, AFragmentedStrayCountsOnceWhenItsLastFragmentComes) {
  poll_.start(kT0);
  poll_.send_idle_before_release(kT0);
  const auto frames = fragments_of(std::vector<std::uint8_t>(10, 7));
  poll_.take_stray(frames[0].payload());
  EXPECT_TRUE(poll_.strays_expected());
  poll_.take_stray(frames.back().payload());
  EXPECT_FALSE(poll_.strays_expected());
}

}  // namespace
}  // namespace dnbridge::devicenet
