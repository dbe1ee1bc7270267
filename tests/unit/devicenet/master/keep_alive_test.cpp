// The explicit connection's keep-alive on its own: one per EPR from going
// online, Identity.Status and Identity.State read in turn (Status alone
// without State), none doubled while one is unanswered, an unanswered one
// sent again at once until 4 x EPR of silence loses the connection.
#include "bridge/devicenet/master/keep_alive.hpp"

#include <gtest/gtest.h>

namespace dnbridge::devicenet {
namespace {

const TimePoint kT0 = TimePoint{} + seconds(100);

// The attribute the keep-alive due at `now` reads; 0 when none goes.
unsigned read_at(KeepAlive& k, TimePoint now, bool outstanding = false) {
  const cip::AttributeRef* read = k.on_timer(now, outstanding);
  return read ? read->attribute : 0u;
}

const unsigned kStatus = cip::identity::kStatus.attribute;
const unsigned kState = cip::identity::kState.attribute;

TEST(KeepAlive, OnePerEprFromGoingOnline) {
  KeepAlive k(milliseconds(2500));
  EXPECT_EQ(read_at(k, kT0 + seconds(60)), 0u) << "none before the node is online";
  k.set_epr(milliseconds(2000));  // the device's rounding
  k.start(kT0);
  EXPECT_EQ(k.next(), kT0 + milliseconds(2000));
  EXPECT_EQ(read_at(k, kT0 + milliseconds(1999)), 0u);
  EXPECT_NE(read_at(k, kT0 + milliseconds(2003)), 0u);
  EXPECT_EQ(k.next(), kT0 + milliseconds(4003)) << "an EPR after it went";
  k.stop();
  EXPECT_EQ(k.next(), kNever);
  EXPECT_EQ(read_at(k, kT0 + seconds(60)), 0u);
}

TEST(KeepAlive, StatusAndStateInTurnStatusAloneWithoutState) {
  KeepAlive k(milliseconds(1000));
  k.start(kT0);
  EXPECT_EQ(read_at(k, kT0 + seconds(1)), kStatus);
  EXPECT_TRUE(k.reads_status());
  EXPECT_EQ(read_at(k, kT0 + seconds(2)), kState);
  EXPECT_FALSE(k.reads_status());
  EXPECT_EQ(read_at(k, kT0 + seconds(3)), kStatus);
  k.set_state_supported(false);
  EXPECT_EQ(read_at(k, kT0 + seconds(4)), kStatus);
  EXPECT_EQ(read_at(k, kT0 + seconds(5)), kStatus);
  EXPECT_TRUE(k.reads_status());
}

TEST(KeepAlive, OneStillUnansweredIsNotDoubledButThePeriodGoesOn) {
  KeepAlive k(milliseconds(1000));
  k.start(kT0);
  EXPECT_EQ(read_at(k, kT0 + seconds(1)), kStatus);
  EXPECT_EQ(read_at(k, kT0 + seconds(2), /*outstanding=*/true), 0u);
  EXPECT_EQ(k.next(), kT0 + seconds(3)) << "rescheduled all the same";
  EXPECT_EQ(read_at(k, kT0 + seconds(3)), kState) << "the turn skipped nothing";
}

TEST(KeepAlive, LostOnlyAfterFourEprsWithoutAnAnswer) {
  KeepAlive k(milliseconds(500));
  k.start(kT0);
  k.answered(kT0 + milliseconds(600));
  EXPECT_FALSE(k.lost(kT0 + milliseconds(2599)));
  k.again(kT0 + milliseconds(2599));
  EXPECT_NE(read_at(k, kT0 + milliseconds(2599)), 0u) << "an unanswered one goes again at once";
  EXPECT_TRUE(k.lost(kT0 + milliseconds(2600)));
  EXPECT_EQ(k.silence(kT0 + milliseconds(2600)), milliseconds(2000));
}

}  // namespace
}  // namespace dnbridge::devicenet
