// Releasing what the master holds of a node: one Release of everything; a
// device that refuses it whole (0x0B, it lacks one of them) gets one
// connection at a time, the I/O connections first, the explicit one last,
// whatever each answer; a single connection refused is not retried.
#include "bridge/devicenet/master/release_sequence.hpp"

#include <gtest/gtest.h>

namespace dnbridge::devicenet {
namespace {

constexpr std::uint8_t kAll =
    allocation::kExplicit | allocation::kPoll | allocation::kChangeOfState;

// Any answer but 0x0B to the Release of everything (done, a timeout from a
// device gone, another status) ends it: nothing is released one by one.
TEST(ReleaseSequence, AnsweredWholeIsDone) {
  ReleaseSequence s;
  s.begin();
  EXPECT_EQ(s.after(kAll, false), 0);
}

TEST(ReleaseSequence, RefusedWholeGoesOneAtATimeExplicitLast) {
  ReleaseSequence s;
  s.begin();
  EXPECT_EQ(s.after(kAll, true), allocation::kPoll) << "the lowest I/O bit first";
  EXPECT_EQ(s.after(allocation::kPoll, false), allocation::kChangeOfState);
  // Refused too (the device lacks it): no restart of the sequence.
  EXPECT_EQ(s.after(allocation::kChangeOfState, true), allocation::kExplicit);
  EXPECT_EQ(s.after(allocation::kExplicit, true), 0);
  EXPECT_EQ(s.after(allocation::kExplicit, true), 0) << "done stays done";
}

TEST(ReleaseSequence, ASingleConnectionRefusedIsNotRetried) {
  ReleaseSequence s;
  s.begin();
  EXPECT_EQ(s.after(allocation::kExplicit, true), 0);
}

TEST(ReleaseSequence, BeginForgetsASequenceInHand) {
  ReleaseSequence s;
  s.begin();
  ASSERT_EQ(s.after(kAll, true), allocation::kPoll);
  s.begin();
  EXPECT_EQ(s.after(allocation::kExplicit | allocation::kPoll, true), allocation::kPoll)
      << "a new Release refused whole starts its own sequence";
  EXPECT_EQ(s.after(allocation::kPoll, false), allocation::kExplicit);
  EXPECT_EQ(s.after(allocation::kExplicit, false), 0);
}

}  // namespace
}  // namespace dnbridge::devicenet
