// Explicit messaging topics: requests are volatile (a bridge never executes a
// request written before it was there), replies reach a requester whose
// reader the bridge discovers late.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

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
  Writer<dnbridge_ExplicitRequest> client(participant_, topic, request_writer_qos());
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());

  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic, request_reader_qos());
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
  Reader<dnbridge_ExplicitRequest> bridge(participant_, topic, request_reader_qos());
  Writer<dnbridge_ExplicitRequest> client(participant_, topic, request_writer_qos());
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());
  ASSERT_TRUE(client.write(*request(rack_, 1)).ok());
  ASSERT_TRUE(client.write(*request(rack_, 2)).ok());
  ASSERT_TRUE(client.wait_for_acks(kEventTimeout).ok());
  auto taken = bridge.take();
  ASSERT_TRUE(taken.ok());
  EXPECT_EQ(taken->size(), 3U);
}

TEST_F(DdsTest, ReplyReachesARequesterDiscoveredAfterIt) {
  Topic<dnbridge_ExplicitReply> topic(participant_);
  Writer<dnbridge_ExplicitReply> bridge(participant_, topic, reply_writer_qos());
  ASSERT_TRUE(bridge.write(*reply(rack_, 41)).ok());
  ASSERT_TRUE(bridge.write(*reply(rack_, 42)).ok());

  Reader<dnbridge_ExplicitReply> client(participant_, topic, reply_reader_qos());
  ReadCondition any(client, DDS_ANY_STATE);
  ASSERT_TRUE(wait_for(participant_, any));
  auto taken = client.take();
  ASSERT_TRUE(taken.ok());
  ASSERT_EQ(taken->size(), 2U);
  EXPECT_EQ(view((*taken)[0]->message), "done");
}

}  // namespace
}  // namespace dnbridge::dds::testing
