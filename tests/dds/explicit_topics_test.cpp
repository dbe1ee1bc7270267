// Explicit messaging topics: requests are volatile (a bridge never executes a
// request written before it was there), replies reach a requester whose
// reader the bridge discovers late.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "dds_fixture.hpp"

namespace dnbridge::dds::testing {
namespace {

Owned<dnbridge_ExplicitRequest> request(const std::string& requester, std::uint32_t txid) {
  Owned<dnbridge_ExplicitRequest> r;
  set_string(r->requester, requester);
  r->txid = txid;
  r->command = dnbridge_COMMAND_EXECUTE;
  return r;
}

Owned<dnbridge_ExplicitReply> reply(const std::string& requester, std::uint32_t txid) {
  Owned<dnbridge_ExplicitReply> r;
  set_string(r->requester, requester);
  r->txid = txid;
  r->status = dnbridge_STATUS_SUCCESS;
  set_string(r->message, "done");
  return r;
}

TEST_F(DdsTest, RequestWrittenBeforeTheBridgeIsNeverDelivered) {
  Topic<dnbridge_ExplicitRequest> topic(participant_);
  Writer<dnbridge_ExplicitRequest> client(participant_, topic,
                                          request_writer_qos(rack_partitions(rack_)));
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());

  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic,
                                          request_reader_qos(rack_partitions(rack_)));
  ASSERT_TRUE(client.write(*request(rack_, 2)).ok());
  ReadCondition any(bridge, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = bridge.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 1U);
  EXPECT_EQ((*taken)[0]->txid, 2U);
}

TEST_F(DdsTest, RepeatedRequestsOfOneTransactionAreAllKept) {
  // Keep-all: a repeated request is not overwritten before the bridge takes it.
  Topic<dnbridge_ExplicitRequest> topic(participant_);
  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic,
                                          request_reader_qos(rack_partitions(rack_)));
  Writer<dnbridge_ExplicitRequest> client(participant_, topic,
                                          request_writer_qos(rack_partitions(rack_)));
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());
  ASSERT_TRUE(client.write(*request(rack_, 2)).ok());
  ASSERT_TRUE(client.wait_for_acks(kEventTimeout).ok());
  auto taken = bridge.take();
  ASSERT_TRUE(taken.ok());
  EXPECT_EQ(taken->size(), 3U);
}

TEST_F(DdsTest, RequestReaderNeverRefusesASample) {
  // Untaken repeats of one transaction and hundreds of transactions left
  // registered: the bridge's reader keeps the newest kExplicitHistoryDepth of
  // each and refuses nothing, so no write waits (a refused reliable sample
  // would block the writer here, and across processes the delivery thread
  // every reader of the participant shares).
  Topic<dnbridge_ExplicitRequest> topic(participant_);
  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic,
                                          request_reader_qos(rack_partitions(rack_)));
  Writer<dnbridge_ExplicitRequest> client(participant_, topic,
                                          request_writer_qos(rack_partitions(rack_)));
  const auto r = request(rack_, 1);
  for (int32_t i = 0; i < 2 * kExplicitHistoryDepth; ++i) ASSERT_TRUE(client.write(*r).ok()) << i;
  EXPECT_EQ(bridge.take()->size(), static_cast<std::size_t>(kExplicitHistoryDepth));
  constexpr std::uint32_t kRegistered = 600;
  std::size_t taken = 0;
  for (std::uint32_t txid = 2; txid < 2 + kRegistered; ++txid) {
    ASSERT_TRUE(client.write(*request(rack_, txid)).ok()) << txid;
    if (txid % 100 == 0) taken += bridge.take()->size();
  }
  for (auto more = bridge.take(); more.ok() && !more->empty(); more = bridge.take()) {
    taken += more->size();
  }
  EXPECT_EQ(taken, kRegistered);
}

TEST_F(DdsTest, ARequesterNameWithANulInsideIsSeenWhole) {
  // A client in another language can send "ab\0x": the C struct reads "ab".
  // The serialized form the bridge takes with it shows the whole name.
  Topic<dnbridge_ExplicitRequest> topic(participant_);
  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic,
                                          request_reader_qos(rack_partitions(rack_)));
  Writer<dnbridge_ExplicitRequest> client(participant_, topic,
                                          request_writer_qos(rack_partitions(rack_)));
  ReadCondition fresh(bridge, DDS_NOT_READ_SAMPLE_STATE);
  TakeBuffer<dnbridge_ExplicitRequest> buffer(4);
  std::vector<std::vector<unsigned char>> serialized;

  ASSERT_TRUE(client.write(*request("abXx", 1)).ok());
  ASSERT_TRUE(wait_for(participant_, fresh));
  ASSERT_EQ(*bridge.take(buffer, serialized), 1u);
  EXPECT_EQ(view(buffer.data(0).requester), "abXx");
  EXPECT_FALSE(leading_string_has_nul(serialized[0]));

  // The same bytes with the X made a NUL, written as they are.
  ASSERT_TRUE(client.write(*request("abXx", 2)).ok());
  ASSERT_TRUE(wait_for(participant_, fresh));
  Serialized with_nul = take_serialized(bridge);
  ASSERT_TRUE(put_nul(with_nul, "Xx"));
  ASSERT_EQ(write_serialized(client, std::move(with_nul)), DDS_RETCODE_OK);
  ASSERT_TRUE(wait_for(participant_, fresh));
  ASSERT_EQ(*bridge.take(buffer, serialized), 1u);
  EXPECT_EQ(view(buffer.data(0).requester), "ab");
  EXPECT_TRUE(leading_string_has_nul(serialized[0]));

  // A transaction the requester unregisters (as every requester does after
  // its reply): a sample without data, taken without bytes.
  ASSERT_TRUE(client.unregister_instance(*request("abXx", 1)).ok());
  ASSERT_TRUE(wait_for(participant_, fresh));
  ASSERT_EQ(*bridge.take(buffer, serialized), 1u);
  EXPECT_FALSE(buffer.info(0).valid_data());
  EXPECT_NE(buffer.info(0).instance_state(), InstanceState::kAlive);
  EXPECT_TRUE(serialized[0].empty());
}

TEST(LeadingString, ANulIsFoundOnlyInsideAStringThatParses) {
  using Bytes = std::vector<unsigned char>;
  const auto has_nul = [](const Bytes& b) { return leading_string_has_nul(b); };
  // Little endian (encapsulation 00 01), "ab\0x" and its terminating NUL.
  EXPECT_TRUE(has_nul(Bytes{0, 1, 0, 0, 5, 0, 0, 0, 'a', 'b', 0, 'x', 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 5, 0, 0, 0, 'a', 'b', 'y', 'x', 0}));
  // Big endian (00 00).
  EXPECT_TRUE(has_nul(Bytes{0, 0, 0, 0, 0, 0, 0, 3, 0, 'b', 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 0, 0, 0, 0, 0, 0, 3, 'a', 'b', 0}));
  // A NUL at the start counts; the terminating one alone does not.
  EXPECT_TRUE(has_nul(Bytes{0, 1, 0, 0, 2, 0, 0, 0, 0, 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 1, 0, 0, 0, 0}));
  // What does not parse: too short, a length past the end, a huge length.
  EXPECT_FALSE(has_nul(Bytes{}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 5, 0, 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 9, 0, 0, 0, 'a', 0, 'b', 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0}));
  EXPECT_FALSE(has_nul(Bytes{0, 1, 0, 0, 0, 0, 0, 0}));
}

TEST_F(DdsTest, UnregisteredTransactionsFreeTheirInstances) {
  // A reader keeps an instance while a writer has it registered, even with
  // no sample left: a requester unregisters each finished transaction, or
  // its instances add up in every reader.
  Topic<dnbridge_ExplicitRequest> topic(participant_);
  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic,
                                          request_reader_qos(rack_partitions(rack_)));
  Writer<dnbridge_ExplicitRequest> client(participant_, topic,
                                          request_writer_qos(rack_partitions(rack_)));
  ReadCondition not_read(bridge, DDS_NOT_READ_SAMPLE_STATE);
  int executed = 0;
  for (std::uint32_t txid = 1; txid <= 512; ++txid) {
    const auto r = request(rack_, txid);
    ASSERT_TRUE(client.write(*r).ok()) << txid;
    ASSERT_TRUE(client.unregister_instance(*r).ok());
    ASSERT_TRUE(wait_for(participant_, not_read));
    auto taken = bridge.take();
    ASSERT_TRUE(taken.ok());
    for (const auto& sample : *taken) executed += sample.valid_data() ? 1 : 0;
  }
  EXPECT_EQ(executed, 512);
}

TEST_F(DdsTest, ReplyReachesARequesterDiscoveredAfterIt) {
  Topic<dnbridge_ExplicitReply> topic(participant_);
  Writer<dnbridge_ExplicitReply> bridge(participant_, topic,
                                        reply_writer_qos(rack_partitions(rack_)));
  ASSERT_TRUE(bridge.write(*reply(rack_, 41)).ok());
  ASSERT_TRUE(bridge.write(*reply(rack_, 42)).ok());

  Reader<dnbridge_ExplicitReply> client(participant_, topic,
                                        reply_reader_qos(rack_partitions(rack_)));
  ReadCondition any(client, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = client.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 2U);
  EXPECT_EQ(view((*taken)[0]->message), "done");
}

}  // namespace
}  // namespace dnbridge::dds::testing
