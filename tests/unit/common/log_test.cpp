#include "bridge/common/log.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace dnbridge {
namespace {

class Recording final : public LogSink {
 public:
  bool enabled(LogLevel) const noexcept override { return true; }
  void write(LogLevel level, std::string_view, std::string_view message) override {
    levels.push_back(level);
    messages.emplace_back(message);
  }
  std::vector<LogLevel> levels;
  std::vector<std::string> messages;
};

TimePoint at(Duration d) { return TimePoint{} + d; }

TEST(RateLimitedLog, LetsABurstThroughPerWindowAndCountsTheRest) {
  Recording sink;
  const Logger log(sink, "test");
  RateLimitedLog limit(seconds(10), 2);
  for (int i = 1; i <= 5; ++i) {
    EXPECT_EQ(limit.warn(log, at(milliseconds(i)), "message {}", i), i <= 2) << i;
  }
  ASSERT_EQ(sink.messages, (std::vector<std::string>{"message 1", "message 2"}));
  // Still the window that began with message 1: dropped.
  EXPECT_FALSE(limit.warn(log, at(milliseconds(10000)), "message {}", 6));
  // The next window: the first message says how many were not logged.
  EXPECT_TRUE(limit.error(log, at(milliseconds(10001)), "message {}", 7));
  EXPECT_TRUE(limit.warn(log, at(milliseconds(10001)), "message {}", 8));
  ASSERT_EQ(sink.messages.size(), 4u);
  EXPECT_EQ(sink.messages[2], "message 7 (4 more not logged)");
  EXPECT_EQ(sink.levels[2], LogLevel::kError);
  EXPECT_EQ(sink.messages[3], "message 8");
  EXPECT_EQ(sink.levels[3], LogLevel::kWarn);
}

TEST(RateLimitedLog, NamesWhatWasNotLogged) {
  Recording sink;
  const Logger log(sink, "test");
  RateLimitedLog limit(seconds(1), 1, "refusals");
  EXPECT_TRUE(limit.info(log, at(seconds(0)), "refused"));
  EXPECT_FALSE(limit.info(log, at(milliseconds(500)), "refused"));
  EXPECT_TRUE(limit.info(log, at(seconds(1)), "refused"));
  ASSERT_EQ(sink.messages.size(), 2u);
  EXPECT_EQ(sink.messages[1], "refused (1 more refusals not logged)");
  EXPECT_EQ(sink.levels[1], LogLevel::kInfo);
}

}  // namespace
}  // namespace dnbridge
