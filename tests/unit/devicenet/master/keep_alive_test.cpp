// The explicit connection's keep-alive on its own: one per EPR from going
// online, Identity.Status and Identity.State read in turn (Status alone
// without State), an unanswered one sent again at once until 4 x EPR of
// silence loses the connection.
#include "bridge/devicenet/master/keep_alive.hpp"

#include <gtest/gtest.h>

namespace dnbridge::devicenet {
namespace {

const TimePoint kT0 = TimePoint{} + seconds(100);

TEST(KeepAlive, OnePerEprFromGoingOnline) {
  KeepAlive k(milliseconds(2500));
  EXPECT_EQ(k.next(), kNever) << "none before the node is online";
  k.set_epr(milliseconds(2000));  // the device's rounding
  k.start(kT0);
  EXPECT_EQ(k.next(), kT0 + milliseconds(2000));
  EXPECT_FALSE(k.due(kT0 + milliseconds(1999)));
  EXPECT_TRUE(k.due(kT0 + milliseconds(2003)));
  EXPECT_EQ(k.next(), kT0 + milliseconds(4003)) << "an EPR after it went";
  k.stop();
  EXPECT_EQ(k.next(), kNever);
  EXPECT_FALSE(k.due(kT0 + seconds(60)));
}

TEST(KeepAlive, StatusAndStateInTurnStatusAloneWithoutState) {
  KeepAlive k(milliseconds(1000));
  EXPECT_EQ(k.next_read().attribute, cip::identity::kStatus.attribute);
  EXPECT_TRUE(k.reads_status());
  EXPECT_EQ(k.next_read().attribute, cip::identity::kState.attribute);
  EXPECT_FALSE(k.reads_status());
  EXPECT_EQ(k.next_read().attribute, cip::identity::kStatus.attribute);
  k.set_state_supported(false);
  EXPECT_EQ(k.next_read().attribute, cip::identity::kStatus.attribute);
  EXPECT_EQ(k.next_read().attribute, cip::identity::kStatus.attribute);
  EXPECT_TRUE(k.reads_status());
}

TEST(KeepAlive, LostOnlyAfterFourEprsWithoutAnAnswer) {
  KeepAlive k(milliseconds(500));
  k.start(kT0);
  k.answered(kT0 + milliseconds(600));
  EXPECT_FALSE(k.lost(kT0 + milliseconds(2599)));
  k.again(kT0 + milliseconds(2599));
  EXPECT_TRUE(k.due(kT0 + milliseconds(2599))) << "an unanswered one goes again at once";
  EXPECT_TRUE(k.lost(kT0 + milliseconds(2600)));
  EXPECT_EQ(k.silence(kT0 + milliseconds(2600)), milliseconds(2000));
}

}  // namespace
}  // namespace dnbridge::devicenet
