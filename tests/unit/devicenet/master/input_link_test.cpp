// The input connection on its own: its allocation choice and EPR by kind,
// what a new attempt forgets, messages taken and acknowledged, the device's
// retries kept from the layer above, bad sizes, and its watchdog.
#include "bridge/devicenet/master/input_link.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::devicenet {
namespace {

const TimePoint kT0 = TimePoint{} + seconds(100);

struct Wire final : can::FrameSink {
  void send(const can::CanFrame& f, TimePoint) override { frames.push_back(f); }
  std::vector<can::CanFrame> frames;
};

struct Inputs final : InputLink::Listener {
  void on_inputs(Bytes data, TimePoint) override { taken.emplace_back(data.begin(), data.end()); }
  void on_bad_inputs(NodeError::Kind kind, std::uint32_t got, TimePoint) override {
    bad.push_back(kind);
    bad_sizes.push_back(got);
  }
  std::vector<std::vector<std::uint8_t>> taken;
  std::vector<NodeError::Kind> bad;
  std::vector<std::uint32_t> bad_sizes;
};

class InputLinkTest : public ::testing::Test {
 protected:
  InputLinkTest() {
    config_.mac = MacId::from(12).value();
    config_.expected_packet_rate = milliseconds(300);
    InputConnection in;
    in.kind = InputKind::kChangeOfState;
    in.expected_packet_rate = milliseconds(100);
    in.produced_size = 2;
    config_.profile.input_connection = in;
  }
  InputConnection& in() { return *config_.profile.input_connection; }

  NodeConfig config_;
  Wire wire_;
  NodeCounters counters_;
  Inputs inputs_;
  InputLink link_{config_, wire_, counters_, inputs_};
};

TEST_F(InputLinkTest, TheChoiceAndTheEprFollowTheKind) {
  EXPECT_EQ(link_.choice(), allocation::kChangeOfState);
  in().acknowledged = false;
  EXPECT_EQ(link_.choice(), allocation::kChangeOfState | allocation::kAckSuppression);
  EXPECT_EQ(link_.connection_bits(), allocation::kChangeOfState) << "Release names no suppression";
  in().kind = InputKind::kCyclic;
  EXPECT_EQ(link_.choice(), allocation::kCyclic | allocation::kAckSuppression);
  EXPECT_EQ(link_.epr_asked(), milliseconds(100));
  in().kind = InputKind::kBitStrobe;
  EXPECT_EQ(link_.choice(), allocation::kBitStrobe);
  EXPECT_EQ(link_.epr_asked(), milliseconds(300)) << "a bit-strobe connection takes the node's";

  config_.profile.input_connection.reset();
  EXPECT_EQ(link_.configured(), nullptr);
  EXPECT_EQ(link_.choice(), 0);
  EXPECT_EQ(link_.epr_asked(), Duration::zero());
}

TEST_F(InputLinkTest, ANewAttemptForgetsWhatTheLastOneLearnt) {
  link_.begin_attempt();
  link_.set_ack_timer(milliseconds(40));
  link_.set_retry_limit(3);
  link_.note_ack_handler_unread();
  link_.set_path_refusal("; Set of its path refused");
  link_.allocation().release_tried = true;
  link_.start_consuming(kT0);
  EXPECT_EQ(link_.settings()->ack_timer, milliseconds(40));
  EXPECT_NE(link_.describe().find("(defaults: its Acknowledge Handler not read)"),
            std::string::npos);

  link_.stop();
  link_.begin_attempt();
  link_.start_consuming(kT0);
  const CosSettings s = *link_.settings();
  EXPECT_EQ(s.ack_timer, CosSettings{}.ack_timer);
  EXPECT_EQ(s.retry_limit, CosSettings{}.retry_limit);
  EXPECT_EQ(s.expected_packet_rate, milliseconds(100));
  EXPECT_FALSE(s.ack_suppressed);
  EXPECT_TRUE(link_.path_refusal().empty());
  EXPECT_FALSE(link_.allocation().release_tried);
  EXPECT_EQ(link_.describe().find("defaults"), std::string::npos) << link_.describe();

  in().kind = InputKind::kBitStrobe;
  link_.begin_attempt();
  link_.start_consuming(kT0);
  EXPECT_TRUE(link_.settings()->ack_suppressed) << "nothing acknowledges a bit-strobe response";
}

TEST_F(InputLinkTest, MessagesAreAcknowledgedAndRetriesAreNotReportedAgain) {
  link_.begin_attempt();
  EXPECT_FALSE(link_.consuming());
  EXPECT_EQ(link_.watchdog_deadline(), kNever);
  link_.start_consuming(kT0);
  link_.set_epr(milliseconds(120));  // the device's rounding
  EXPECT_EQ(link_.settings()->expected_packet_rate, milliseconds(120));

  const std::vector<std::uint8_t> a{0x01, 0x00};
  link_.on_message(Bytes(a), kT0 + milliseconds(5));
  link_.on_message(Bytes(a), kT0 + milliseconds(26));  // its ack missed: the device's retry
  ASSERT_EQ(inputs_.taken.size(), 1u);
  EXPECT_EQ(inputs_.taken[0], a);
  EXPECT_EQ(wire_.frames.size(), 2u) << "the retry is acknowledged as well";
  EXPECT_EQ(counters_.cos_messages, 2u);
  EXPECT_EQ(counters_.cos_retries, 1u);
  EXPECT_EQ(counters_.cos_acks, 2u);
  EXPECT_EQ(std::vector<std::uint8_t>(link_.last_data().begin(), link_.last_data().end()), a);
  EXPECT_NE(link_.describe().find("on change of state (EPR 120 ms, acknowledged"),
            std::string::npos)
      << link_.describe();
}

TEST_F(InputLinkTest, AMessageOfAnotherSizeIsBadAndAGoodOneEndsTheRun) {
  link_.begin_attempt();
  link_.start_consuming(kT0);
  const std::vector<std::uint8_t> three{1, 2, 3};
  link_.on_message(Bytes(three), kT0);
  ASSERT_EQ(inputs_.bad.size(), 1u);
  EXPECT_EQ(inputs_.bad[0], NodeError::Kind::kCosLength);
  EXPECT_EQ(inputs_.bad_sizes[0], 3u);
  EXPECT_EQ(link_.errors_in_a_row(), 0u) << "the node counts the bad ones";
  EXPECT_EQ(link_.count_error(), 1u);
  const std::vector<std::uint8_t> two{1, 2};
  link_.on_message(Bytes(two), kT0 + milliseconds(1));
  EXPECT_EQ(link_.errors_in_a_row(), 0u);

  in().kind = InputKind::kBitStrobe;
  link_.on_message(Bytes(three), kT0 + milliseconds(2));
  EXPECT_EQ(inputs_.bad.back(), NodeError::Kind::kStrobeLength);
}

TEST_F(InputLinkTest, FourEprsOfSilenceExpireTheWatchdogOnce) {
  link_.begin_attempt();
  link_.start_consuming(kT0);
  EXPECT_EQ(link_.watchdog_deadline(), kT0 + milliseconds(400));
  EXPECT_FALSE(link_.watchdog_expired(kT0 + milliseconds(399)));
  EXPECT_TRUE(link_.watchdog_expired(kT0 + milliseconds(400)));
  EXPECT_FALSE(link_.watchdog_expired(kT0 + milliseconds(401))) << "once per loss";
  link_.stop();
  EXPECT_FALSE(link_.consuming());
  EXPECT_FALSE(link_.settings().has_value());
  EXPECT_TRUE(link_.describe().empty());
}

}  // namespace
}  // namespace dnbridge::devicenet
