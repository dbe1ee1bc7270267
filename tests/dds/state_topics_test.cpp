// The state topics' QoS contract (topics.hpp) as Cyclone DDS carries it out:
// source timestamps, late joiners, keep-last 1, deadlines, and what readers
// see when a bridge unregisters its instances or goes away.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {
namespace {

Owned<dnbridge_PumpState> pump_state(const std::string& rack, std::uint8_t mac,
                                     std::uint16_t analog_output_raw) {
  Owned<dnbridge_PumpState> s;
  set_string(s->rack, rack);
  set_string(s->port, "port-a");
  s->mac = mac;
  s->online = true;
  s->analog_output_raw = analog_output_raw;
  return s;
}

class StateTopicTest : public DdsTest {
 protected:
  Topic<dnbridge_PumpState> topic_{participant_};
};

TEST_F(StateTopicTest, SourceTimestampIsCarried) {
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  // A CAN receive time well in the past, to the nanosecond.
  const Timestamp received = dds_now() - seconds(3) + std::chrono::nanoseconds(123);
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 100), received).ok());

  ReadCondition any(reader, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_EQ((*taken)[0].info().source_timestamp(), received);
  EXPECT_EQ((*taken)[0].info().publication_handle(), writer.instance_handle().value());
}

TEST_F(StateTopicTest, LateReaderGetsLastStateAtOnce) {
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 100)).ok());
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 101)).ok());
  ASSERT_TRUE(writer.write(*pump_state(rack_, 2, 200)).ok());

  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  ReadCondition any(reader, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 2U);  // the last state of each instance only
  for (const auto& sample : *taken) {
    ASSERT_TRUE(sample.valid_data());
    EXPECT_EQ(sample->analog_output_raw, sample->mac == 1 ? 101 : 200);
  }
}

TEST_F(StateTopicTest, ReaderKeepsLastSamplePerInstance) {
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  for (std::uint16_t v = 1; v <= 3; ++v) ASSERT_TRUE(writer.write(*pump_state(rack_, 1, v)).ok());
  for (std::uint16_t v = 11; v <= 12; ++v) ASSERT_TRUE(writer.write(*pump_state(rack_, 2, v)).ok());
  ASSERT_TRUE(writer.wait_for_acks(kEventTimeout).ok());

  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 2U);
  for (const auto& sample : *taken) EXPECT_EQ(sample->analog_output_raw, sample->mac == 1 ? 3 : 12);
}

TEST_F(StateTopicTest, OlderSourceTimestampIsDropped) {
  // Destination order by source timestamp: a late-arriving older state never
  // overwrites a newer one.
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  const Timestamp t = dds_now();
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 2), t).ok());
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 1), t - milliseconds(5)).ok());
  ASSERT_TRUE(writer.wait_for_acks(kEventTimeout).ok());

  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_EQ((*taken)[0]->analog_output_raw, 2);
}

TEST_F(StateTopicTest, DeletedWriterLeavesInstancesWithNoWritersNotDisposed) {
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  auto writer = std::make_unique<Writer<dnbridge_PumpState>>(participant_, topic_,
                                                             state_writer_qos(seconds(1)));
  ASSERT_TRUE(writer->write(*pump_state(rack_, 1, 7)).ok());
  ReadCondition not_read(reader, DDS_NOT_READ_SAMPLE_STATE);
  ASSERT_TRUE(wait_for(participant_, not_read));
  ASSERT_EQ(reader.take(not_read)->size(), 1U);

  writer.reset();  // the bridge goes away
  ASSERT_TRUE(wait_for(participant_, not_read));
  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  const auto& sample = (*taken)[0];
  EXPECT_FALSE(sample.valid_data());  // only the instance state changed
  EXPECT_EQ(sample.info().instance_state(), InstanceState::kNotAliveNoWriters);
  EXPECT_EQ(sample->mac, 1);  // the key members are filled in
  EXPECT_EQ(view(sample->rack), rack_);
}

TEST_F(StateTopicTest, UnregisteredInstanceIsNotReplayedToLateReaders) {
  // At shutdown the bridge unregisters its state instances: a reader that
  // joins afterwards must not take the last state of a bridge that is gone
  // for current. (Cyclone drops an unregistered instance from the
  // transient-local history.)
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  ASSERT_TRUE(writer.write(*pump_state(rack_, 1, 7)).ok());
  ASSERT_TRUE(writer.write(*pump_state(rack_, 2, 8)).ok());
  ASSERT_TRUE(writer.unregister_instance(*pump_state(rack_, 1, 0)).ok());

  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos());
  ReadCondition any(reader, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = reader.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_EQ((*taken)[0]->mac, 2);
}

TEST_F(StateTopicTest, DeadlineMissedWhenWriterStops) {
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos(milliseconds(60)));
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(milliseconds(30)));
  ASSERT_TRUE(reader.set_status_mask(DDS_REQUESTED_DEADLINE_MISSED_STATUS).ok());
  ASSERT_TRUE(writer.set_status_mask(DDS_OFFERED_DEADLINE_MISSED_STATUS).ok());
  const auto key = pump_state(rack_, 1, 7);
  ASSERT_TRUE(writer.write(*key).ok());
  // ... and nothing more is written.

  ASSERT_TRUE(wait_for(participant_, reader));
  auto missed = reader.requested_deadline_missed();
  ASSERT_TRUE(missed.ok());
  EXPECT_GE(missed->total_count, 1U);
  EXPECT_EQ(missed->last_instance_handle, reader.lookup_instance(*key));

  ASSERT_TRUE(wait_for(participant_, writer));
  auto offered = writer.offered_deadline_missed();
  ASSERT_TRUE(offered.ok());
  EXPECT_GE(offered->total_count, 1U);
}

TEST_F(StateTopicTest, ReaderAskingAShorterDeadlineThanOfferedDoesNotMatch) {
  Writer<dnbridge_PumpState> writer(participant_, topic_, state_writer_qos(seconds(1)));
  Reader<dnbridge_PumpState> reader(participant_, topic_, state_reader_qos(milliseconds(500)));
  ASSERT_TRUE(reader.set_status_mask(DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS).ok());
  ASSERT_TRUE(wait_for(participant_, reader));
  auto incompatible = reader.requested_incompatible_qos();
  ASSERT_TRUE(incompatible.ok());
  EXPECT_EQ(incompatible->last_policy_id, DDS_DEADLINE_QOS_POLICY_ID);
  EXPECT_EQ(reader.matched_publications().value(), 0U);
}

}  // namespace
}  // namespace dnbridge::dds::testing
