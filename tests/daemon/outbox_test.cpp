// The outbox the DDS writes run from: in order, the newest sample of an
// instance only, bounded, and drained on demand. Its thread is held on a
// job of the test's own while the test posts, so that what waits is known.
#include "adapters/daemon/outbox.hpp"

#include <gtest/gtest.h>

#include <array>
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
  // A second hold, after the first was released.
  void hold_again() {
    held_ = {};
    release_ = {};
    hold();
  }
  void release_again() { release(); }
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

TEST_F(OutboxTest, RunsJobsInOrderAndAKeyedJobOnlyInItsNewestForm) {
  hold();
  box_.post("pump 1", [this] { record("pump 1 first"); });
  box_.post([this] { record("reply"); });
  box_.post("pump 2", [this] { record("pump 2"); });
  box_.post("pump 1", [this] { record("pump 1 newest"); });  // in the first one's place
  EXPECT_EQ(box_.counters().waiting, 3u);
  release();
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran(), (std::vector<std::string>{"pump 1 newest", "reply", "pump 2"}));
  const auto c = box_.counters();
  EXPECT_EQ(c.replaced, 1u);
  EXPECT_EQ(c.run, 4u);  // the held job too
  EXPECT_EQ(c.waiting, 0u);
}

// A node removed (its instances disposed after its last sample) and added
// again before the outbox caught up: the new node's samples come after the
// disposal, not in the place of the old node's last one.
TEST_F(OutboxTest, AJobAfterKeysRunsAfterTheirWaitingJobsAndBeforeTheirLaterOnes) {
  hold();
  box_.post("pump 1", [this] { record("pump 1 last"); });
  box_.post("pump 2", [this] { record("pump 2"); });
  const std::array<std::string, 1> keys{"pump 1"};
  box_.post_always_after(keys, [this] { record("pump 1 disposed"); });
  box_.post("pump 1", [this] { record("pump 1 again"); });
  box_.post("pump 1", [this] { record("pump 1 again, newest"); });  // replaces the one after
  box_.post("pump 2", [this] { record("pump 2 newest"); });         // in its place, before
  release();
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran(), (std::vector<std::string>{"pump 1 last", "pump 2 newest", "pump 1 disposed",
                                             "pump 1 again, newest"}));
  // Keyed again from then on.
  hold_again();
  box_.post("pump 1", [this] { record("a"); });
  box_.post("pump 1", [this] { record("b"); });
  release_again();
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran().back(), "b");
  EXPECT_EQ(ran().size(), 5u);
}

TEST_F(OutboxTest, UnkeyedJobsPastTheCapacityAreRefusedNotQueued) {
  hold();
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(box_.post([this, i] { record(std::to_string(i)); }));
  EXPECT_FALSE(box_.post([this] { record("refused"); }));
  // What must not be lost goes in anyway; keyed jobs are bounded by their keys.
  box_.post_always([this] { record("unregister"); });
  box_.post("pump 1", [this] { record("pump 1"); });
  EXPECT_EQ(box_.counters().refused, 1u);
  release();
  ASSERT_TRUE(box_.drain(kBound));
  EXPECT_EQ(ran(), (std::vector<std::string>{"0", "1", "2", "unregister", "pump 1"}));
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
