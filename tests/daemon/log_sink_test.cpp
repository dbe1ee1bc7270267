// The bridge's log: lines on standard error with the time to the
// millisecond; under systemd, journal entries with their priority and
// structured fields, and a line on standard error should the journal refuse.
#include "adapters/daemon/log_sink.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "adapters/daemon/dds_input.hpp"

namespace dnbridge::daemon {
namespace {

std::string read_all(std::FILE* f) {
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s += static_cast<char>(c);
  return s;
}

TEST(LogSink, LinesHaveTheTimeToTheMillisecond) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  StderrLogSink sink(LogLevel::kInfo, out);
  ASSERT_FALSE(sink.to_journal());  // not standard error: never the journal
  Logger log(sink, "port A");
  log.with("MAC", "3").warn("node 3 online -> absent: {}", "no poll response");
  log.debug("not logged at info");
  const std::string text = read_all(out);
  std::fclose(out);
  EXPECT_TRUE(std::regex_match(
      text,
      std::regex(
          R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z warn  port A: node 3 online -> absent: no poll response\n)")))
      << text;
}

TEST(LogSink, JournalEntriesCarryPriorityComponentAndFields) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  StderrLogSink sink(LogLevel::kInfo, out);
  sink.add_field("RACK", "etch-3");
  std::vector<std::vector<std::string>> entries;
  int answer = 0;
  sink.send_to_journal([&](std::span<const std::string> fields) {
    entries.emplace_back(fields.begin(), fields.end());
    return answer;
  });
  const Logger port = Logger(sink, "port A").with("PORT", "A");
  port.named("port A node 12")
      .with("MAC", "12")
      .with("NODE", "12")
      .with("NODE_STATE", "absent")
      .warn("online -> absent: {}", "no poll response for 2000 ms");
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0],
            (std::vector<std::string>{
                "MESSAGE=port A node 12: online -> absent: no poll response for 2000 ms",
                "PRIORITY=4", "COMPONENT=port A node 12", "RACK=etch-3", "PORT=A", "MAC=12",
                "NODE=12", "NODE_STATE=absent"}));
  EXPECT_EQ(read_all(out), "");

  // The journal refuses: the line goes to standard error with its priority.
  answer = -11;
  port.error("bus-off");
  EXPECT_EQ(entries.size(), 2u);
  EXPECT_EQ(read_all(out), "<3>port A: bus-off\n");
  std::fclose(out);
}

TEST(LogSink, StandardErrorIsTheJournalOnlyWhenJournalStreamNamesIt) {
  struct stat st {};
  ASSERT_EQ(::fstat(2, &st), 0);
  const std::string mine = std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  ASSERT_EQ(::unsetenv("JOURNAL_STREAM"), 0);
  EXPECT_FALSE(StderrLogSink::journal_of_stderr());
  ASSERT_EQ(::setenv("JOURNAL_STREAM", (mine + "1").c_str(), 1), 0);  // another stream
  EXPECT_FALSE(StderrLogSink::journal_of_stderr());
  ASSERT_EQ(::setenv("JOURNAL_STREAM", "garbage", 1), 0);
  EXPECT_FALSE(StderrLogSink::journal_of_stderr());
  ASSERT_EQ(::setenv("JOURNAL_STREAM", mine.c_str(), 1), 0);
  EXPECT_TRUE(StderrLogSink::journal_of_stderr());
  ASSERT_EQ(::unsetenv("JOURNAL_STREAM"), 0);
}

TEST(Logger, FieldsAreKeptReplacedAndBounded) {
  class Capture final : public LogSink {
   public:
    bool enabled(LogLevel) const noexcept override { return true; }
    void write(LogLevel, std::string_view, std::string_view) override {}
    void write_structured(LogLevel, std::string_view, std::string_view,
                          std::span<const LogField> f) override {
      fields.clear();
      for (const auto& x : f) fields.push_back(std::string(x.name) + "=" + std::string(x.value));
    }
    std::vector<std::string> fields;
  } sink;
  Logger log = Logger(sink, "c").with("A", "1").with("B", "2").with("A", "3");
  log.info("x");
  EXPECT_EQ(sink.fields, (std::vector<std::string>{"A=3", "B=2"}));
  for (int i = 0; i < 20; ++i) log = log.with("F" + std::to_string(i), "v");
  log.info("x");
  EXPECT_EQ(sink.fields.size(), Logger::kMaxFields);
}

// The command path's lines, written on Cyclone's thread, are said on the
// input thread: in the order written, with their fields, at most kCapacity
// between two drains; the others are counted for the drainer to say.
TEST(HandoffLogSink, KeepsOrderAndFieldsAndCountsWhatItDrops) {
  class Capture final : public LogSink {
   public:
    bool enabled(LogLevel) const noexcept override { return true; }
    void write(LogLevel, std::string_view, std::string_view) override {}
    void write_structured(LogLevel, std::string_view component, std::string_view message,
                          std::span<const LogField> f) override {
      std::string line = std::string(component) + ": " + std::string(message);
      for (const auto& x : f) line += " " + std::string(x.name) + "=" + std::string(x.value);
      lines.push_back(line);
    }
    std::vector<std::string> lines;
  } target;
  int signalled = 0;
  HandoffLogSink sink(target, [&] { ++signalled; });
  Logger log = Logger(sink, "dds input").with("RACK", "r1");
  const std::size_t written = HandoffLogSink::kCapacity + 3;
  for (std::size_t i = 0; i < written; ++i) log.warn("line {}", i);
  EXPECT_TRUE(target.lines.empty());  // nothing said on the writing thread
  EXPECT_EQ(signalled, static_cast<int>(HandoffLogSink::kCapacity));
  EXPECT_EQ(sink.drain(), 3u);
  ASSERT_EQ(target.lines.size(), HandoffLogSink::kCapacity);
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    EXPECT_EQ(target.lines[i], "dds input: line " + std::to_string(i) + " RACK=r1");
  }
  // The count starts again: a drain with nothing waiting drops nothing.
  EXPECT_EQ(sink.drain(), 0u);
  log.warn("after");
  EXPECT_EQ(sink.drain(), 0u);
  EXPECT_EQ(target.lines.back(), "dds input: after RACK=r1");
}

// The input thread's own lines (DdsInput's logger) come after the command
// path's lines handed off before them, not before, though those wait for the
// next drain.
TEST(DrainFirstLogSink, AThreadsOwnLinesComeAfterTheLinesHandedOffBeforeThem) {
  class Capture final : public LogSink {
   public:
    bool enabled(LogLevel) const noexcept override { return true; }
    void write(LogLevel, std::string_view component, std::string_view message) override {
      lines.push_back(std::string(component) + ": " + std::string(message));
    }
    std::vector<std::string> lines;
  } target;
  HandoffLogSink handoff(target, [] {});
  int drains = 0;
  DrainFirstLogSink own(target, [&] {
    ++drains;
    if (handoff.drain() > 0) Logger(own, "input").warn("lines dropped");
  });
  const Logger commands(handoff, "commands");
  const Logger input(own, "input");
  commands.info("one");
  input.info("two");
  commands.info("three");
  commands.info("four");
  input.info("five");
  EXPECT_EQ(target.lines,
            (std::vector<std::string>{"commands: one", "input: two", "commands: three",
                                      "commands: four", "input: five"}));
  EXPECT_EQ(drains, 2);
  // What `before` logs itself is not preceded by another drain.
  for (std::size_t i = 0; i < HandoffLogSink::kCapacity + 1; ++i) commands.info("flood");
  input.info("six");
  EXPECT_EQ(drains, 3);
  ASSERT_GE(target.lines.size(), 2u);
  EXPECT_EQ(target.lines[target.lines.size() - 2], "input: lines dropped");
  EXPECT_EQ(target.lines.back(), "input: six");
}

}  // namespace
}  // namespace dnbridge::daemon
