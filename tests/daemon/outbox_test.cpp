// The outbox the DDS replies are written from: in order, bounded, and
// drained on demand. Its thread is held on a
// job of the test's own while the test posts, so that what waits is known.
#include "adapters/daemon/outbox.hpp"

#include <gtest/gtest.h>

#include <future>
#include <string>
#include <vector>

namespace dnbridge::daemon {
namespace {

constexpr Duration kBound = seconds(5);  // never reached when things work

class OutboxTest : public ::testing::Test {
 protected:
  // Occupies the outbox's thread until release().
  void hold() {
    box_.post([this] {
      held_.set_value();
      release_.get_future().wait();
    });
    held_.get_future().wait();
  }
  void release() { release_.set_value(); }
  void record(std::string what) {
    std::lock_guard lock(mutex_);
    ran_.push_back(std::move(what));
  }
  std::vector<std::string> ran() {
    std::lock_guard lock(mutex_);
    return ran_;
  }

  Outbox box_{"outbox test", 3};
  std::promise<void> held_;
  std::promise<void> release_;
  std::mutex mutex_;
  std::vector<std::string> ran_;
};

TEST_F(OutboxTest, RunsJobsInOrderAndRefusesThosePastTheCapacity) {
  hold();
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(box_.post([this, i] { record(std::to_string(i)); }));
  EXPECT_FALSE(box_.post([this] { record("refused"); }));
  EXPECT_EQ(box_.counters().waiting, 3u);
  EXPECT_EQ(box_.counters().refused, 1u);
  release();
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran(), (std::vector<std::string>{"0", "1", "2"}));
  const auto c = box_.counters();
  EXPECT_EQ(c.run, 4u);  // the held job too
  EXPECT_EQ(c.waiting, 0u);
  EXPECT_TRUE(box_.post([this] { record("room again"); }));
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran().back(), "room again");
}

TEST_F(OutboxTest, DrainWaitsForTheJobsPostedBeforeItOnly) {
  hold();
  box_.post([this] { record("before"); });
  // The thread is held: a drain cannot end in time.
  EXPECT_FALSE(box_.drain(milliseconds(20)));
  release();
  EXPECT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran(), (std::vector<std::string>{"before"}));
}

TEST(Outbox, DestructionRunsWhatStillWaits) {
  std::vector<std::string> ran;
  {
    Outbox box("outbox test", 8);
    std::promise<void> release;
    auto released = release.get_future().share();
    box.post([released] { released.wait(); });
    box.post([&ran] { ran.push_back("last words"); });
    release.set_value();
  }
  EXPECT_EQ(ran, (std::vector<std::string>{"last words"}));
}

}  // namespace
}  // namespace dnbridge::daemon
