#include "bridge/devicenet/wire/identifier.hpp"

#include <gtest/gtest.h>

namespace dnbridge::devicenet {
namespace {

MacId mac(unsigned v) { return MacId::from(v).value(); }

TEST(Identifier, PredefinedSetIdsMatchFactsSheet) {
  // bridge/PROTOCOL.md §1, with slave 3 and master 10.
  EXPECT_EQ(group1_id(Group1Message::kSlavePollResponse, mac(3)), 0x3C3u);
  EXPECT_EQ(group1_id(Group1Message::kSlaveCosCyclic, mac(3)), 0x343u);
  EXPECT_EQ(group1_id(Group1Message::kSlaveBitStrobeResponse, mac(3)), 0x383u);
  EXPECT_EQ(group1_id(Group1Message::kSlaveMulticastPollResponse, mac(3)), 0x303u);
  EXPECT_EQ(group2_id(mac(10), Group2Message::kMasterBitStrobeCommand), 0x450u);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kSlaveExplicitResponse), 0x41Bu);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kMasterExplicitRequest), 0x41Cu);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kMasterIoPoll), 0x41Du);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kUnconnectedExplicitRequest), 0x41Eu);
  EXPECT_EQ(group2_id(mac(3), Group2Message::kDuplicateMacCheck), 0x41Fu);
  EXPECT_EQ(group2_id(mac(63), Group2Message::kDuplicateMacCheck), 0x5FFu);
  EXPECT_EQ(group4_id(Group4Message::kCommFaultedResponse), 0x7ECu);
  EXPECT_EQ(group4_id(Group4Message::kOfflineOwnershipRequest), 0x7EFu);
}

TEST(Identifier, DecodesEachGroup) {
  auto g1 = decode_identifier(0x3C3);
  ASSERT_TRUE(g1.ok());
  EXPECT_EQ(g1->group, MessageGroup::k1);
  EXPECT_EQ(g1->message_id, 0xF);
  EXPECT_EQ(g1->mac, mac(3));

  auto g2 = decode_identifier(0x41E);
  ASSERT_TRUE(g2.ok());
  EXPECT_EQ(g2->group, MessageGroup::k2);
  EXPECT_EQ(g2->message_id, 6);
  EXPECT_EQ(g2->mac, mac(3));

  auto g3 = decode_identifier(0x6C5);  // 1 1 011 000101
  ASSERT_TRUE(g3.ok());
  EXPECT_EQ(g3->group, MessageGroup::k3);
  EXPECT_EQ(g3->message_id, 3);
  EXPECT_EQ(g3->mac, mac(5));

  auto g4 = decode_identifier(0x7EF);
  ASSERT_TRUE(g4.ok());
  EXPECT_EQ(g4->group, MessageGroup::k4);
  EXPECT_EQ(g4->message_id, 0x2F);
}

TEST(Identifier, GroupBoundaries) {
  EXPECT_EQ(decode_identifier(0x3FF)->group, MessageGroup::k1);
  EXPECT_EQ(decode_identifier(0x400)->group, MessageGroup::k2);
  EXPECT_EQ(decode_identifier(0x5FF)->group, MessageGroup::k2);
  EXPECT_EQ(decode_identifier(0x600)->group, MessageGroup::k3);
  EXPECT_EQ(decode_identifier(0x7BF)->group, MessageGroup::k3);
  EXPECT_EQ(decode_identifier(0x7C0)->group, MessageGroup::k4);
}

TEST(Identifier, RejectsInvalidRangeAndExtendedIds) {
  for (std::uint32_t id = 0x7F0; id <= 0x7FF; ++id) {
    auto r = decode_identifier(id);
    ASSERT_FALSE(r.ok()) << std::hex << id;
    EXPECT_EQ(r.error(), Errc::kInvalidIdentifier);
  }
  EXPECT_FALSE(decode_identifier(0x800).ok());
  EXPECT_FALSE(decode_identifier(0x1FFFFFFF).ok());
}

TEST(Identifier, RoundTripsEveryValidId) {
  for (std::uint32_t id = 0; id <= 0x7EF; ++id) {
    auto d = decode_identifier(id);
    ASSERT_TRUE(d.ok()) << id;
    auto e = encode_identifier(*d);
    ASSERT_TRUE(e.ok()) << id;
    EXPECT_EQ(*e, id);
  }
}

TEST(Identifier, EncodeRejectsMessageIdsOutsideTheirGroup) {
  EXPECT_FALSE(encode_identifier({MessageGroup::k1, 16, mac(1)}).ok());
  EXPECT_FALSE(encode_identifier({MessageGroup::k2, 8, mac(1)}).ok());
  EXPECT_FALSE(encode_identifier({MessageGroup::k3, 7, mac(1)}).ok());
  EXPECT_FALSE(encode_identifier({MessageGroup::k4, 0x30, mac(0)}).ok());
}

TEST(MacIdTest, RangeIsZeroToSixtyThree) {
  EXPECT_TRUE(MacId::from(0).has_value());
  EXPECT_TRUE(MacId::from(63).has_value());
  EXPECT_FALSE(MacId::from(64).has_value());
  EXPECT_FALSE(MacId::from(255).has_value());
}

}  // namespace
}  // namespace dnbridge::devicenet
