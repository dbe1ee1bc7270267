// PumpCommand's exclusive ownership: the strongest live writer commands, a
// weaker one takes over when it leaves, and the bridge learns when nobody
// commands any more.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {
namespace {

Owned<dnbridge_PumpCommand> command(const std::string& rack, std::uint16_t analog_output_raw,
                                    const char* issuer) {
  Owned<dnbridge_PumpCommand> c;
  set_string(c->rack, rack);
  set_string(c->port, "port-a");
  c->mac = 9;
  c->pump_on = true;
  c->analog_output_raw = analog_output_raw;
  set_string(c->issuer, issuer);
  return c;
}

class CommandTopicTest : public DdsTest {
 protected:
  // The taken samples, after waiting for at least one.
  std::vector<Sample<dnbridge_PumpCommand>> take_next() {
    EXPECT_TRUE(wait_for(participant_, not_read_));
    auto taken = reader_.take();
    EXPECT_TRUE(taken.ok());
    return taken.ok() ? std::move(*taken) : std::vector<Sample<dnbridge_PumpCommand>>{};
  }
  // Waits until the reader is matched with exactly `count` writers.
  void wait_matched(uint32_t count) {
    ASSERT_TRUE(reader_.set_status_mask(DDS_SUBSCRIPTION_MATCHED_STATUS).ok());
    for (;;) {
      auto matched = reader_.subscription_matched();  // resets the trigger
      ASSERT_TRUE(matched.ok());
      if (matched->current_count == count) break;
      ASSERT_TRUE(wait_for(participant_, reader_));
    }
  }

  Topic<dnbridge_PumpCommand> topic_{participant_};
  Reader<dnbridge_PumpCommand> reader_{participant_, topic_,
                                       command_reader_qos(rack_partitions(rack_))};
  ReadCondition not_read_{reader_, DDS_NOT_READ_SAMPLE_STATE};
};

TEST_F(CommandTopicTest, StrongerWriterOwnsTheInstanceUntilItLeaves) {
  auto weak = std::make_unique<Writer<dnbridge_PumpCommand>>(
      participant_, topic_, command_writer_qos(rack_partitions(rack_), 10, seconds(1)));
  auto strong = std::make_unique<Writer<dnbridge_PumpCommand>>(
      participant_, topic_, command_writer_qos(rack_partitions(rack_), 20, seconds(1)));
  const dds_instance_handle_t strong_handle = strong->instance_handle().value();
  const dds_instance_handle_t weak_handle = weak->instance_handle().value();

  ASSERT_TRUE(strong->write(*command(rack_, 1, "strong")).ok());
  auto taken = take_next();
  ASSERT_EQ(taken.size(), 1U);
  EXPECT_EQ(taken[0]->analog_output_raw, 1);
  EXPECT_EQ(taken[0].info().publication_handle(), strong_handle);

  // The weaker writer's samples are not delivered while the stronger lives.
  ASSERT_TRUE(weak->write(*command(rack_, 2, "weak")).ok());
  ASSERT_TRUE(strong->write(*command(rack_, 3, "strong")).ok());
  ASSERT_TRUE(weak->write(*command(rack_, 4, "weak")).ok());
  ASSERT_TRUE(weak->wait_for_acks(kEventTimeout).ok());
  taken = take_next();
  ASSERT_EQ(taken.size(), 1U);
  EXPECT_EQ(taken[0]->analog_output_raw, 3);
  EXPECT_EQ(view(taken[0]->issuer), "strong");
  EXPECT_EQ(taken[0].info().publication_handle(), strong_handle);
  EXPECT_TRUE(reader_.take()->empty());

  // The stronger leaves: it only unregisters (no autodispose), so the
  // instance stays alive and the weaker writer's next sample is taken.
  strong.reset();
  wait_matched(1);
  ASSERT_TRUE(weak->write(*command(rack_, 5, "weak")).ok());
  taken = take_next();
  ASSERT_EQ(taken.size(), 1U);
  ASSERT_TRUE(taken[0].valid_data());
  EXPECT_EQ(taken[0]->analog_output_raw, 5);
  EXPECT_EQ(taken[0].info().publication_handle(), weak_handle);
  EXPECT_EQ(taken[0].info().instance_state(), InstanceState::kAlive);

  // With no writer left the bridge sees NOT_ALIVE_NO_WRITERS: time to idle.
  weak.reset();
  taken = take_next();
  ASSERT_EQ(taken.size(), 1U);
  EXPECT_FALSE(taken[0].valid_data());
  EXPECT_EQ(taken[0].info().instance_state(), InstanceState::kNotAliveNoWriters);
  EXPECT_EQ(taken[0]->mac, 9);
}

TEST_F(CommandTopicTest, StrongerWriterTakesOverFromAWeakerOne) {
  Writer<dnbridge_PumpCommand> weak(participant_, topic_,
                                    command_writer_qos(rack_partitions(rack_), 10, seconds(1)));
  ASSERT_TRUE(weak.write(*command(rack_, 1, "weak")).ok());
  ASSERT_EQ(take_next().size(), 1U);

  Writer<dnbridge_PumpCommand> strong(participant_, topic_,
                                      command_writer_qos(rack_partitions(rack_), 20, seconds(1)));
  ASSERT_TRUE(strong.write(*command(rack_, 2, "strong")).ok());
  ASSERT_TRUE(weak.write(*command(rack_, 3, "weak")).ok());
  ASSERT_TRUE(weak.wait_for_acks(kEventTimeout).ok());
  auto taken = take_next();
  ASSERT_EQ(taken.size(), 1U);
  EXPECT_EQ(taken[0]->analog_output_raw, 2);
}

TEST_F(CommandTopicTest, SharedOwnershipWriterDoesNotMatch) {
  // Ownership kind must be equal on both sides: a writer that forgot the
  // contract cannot command a pump.
  Qos shared = command_writer_qos(rack_partitions(rack_), 10, seconds(1));
  shared.exclusive_ownership(false);
  Writer<dnbridge_PumpCommand> writer(participant_, topic_, shared);
  ASSERT_TRUE(writer.set_status_mask(DDS_OFFERED_INCOMPATIBLE_QOS_STATUS).ok());
  ASSERT_TRUE(wait_for(participant_, writer));
  EXPECT_EQ(writer.offered_incompatible_qos()->last_policy_id, DDS_OWNERSHIP_QOS_POLICY_ID);
  EXPECT_EQ(writer.matched_subscriptions().value(), 0U);
}

}  // namespace
}  // namespace dnbridge::dds::testing
