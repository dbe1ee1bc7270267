// When the daemon feeds systemd's watchdog, on a fake clock with the port
// loops' progress counters in the test's hands: fed once per interval while
// every loop advances, not at all once one stalls (said once, naming it), and
// again when it advances. And the STATUS= line the service manager shows.
#include "adapters/daemon/watchdog.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "adapters/daemon/service_notify.hpp"

namespace dnbridge::daemon {
namespace {

constexpr TimePoint kStart = TimePoint(seconds(5000));
// WatchdogSec=10 as the unit ships it: WATCHDOG_USEC=10000000, fed every 5 s.
constexpr Duration kInterval = seconds(5);
// The notifier looks every 250 ms.
constexpr Duration kTick = milliseconds(250);

class RecordingLog final : public LogSink {
 public:
  struct Line {
    LogLevel level;
    std::string message;
  };
  bool enabled(LogLevel) const noexcept override { return true; }
  void write(LogLevel level, std::string_view, std::string_view message) override {
    lines.push_back({level, std::string(message)});
  }
  // Lines at `level` containing `text`.
  std::size_t count(LogLevel level, const std::string& text) const {
    std::size_t n = 0;
    for (const auto& l : lines) n += l.level == level && l.message.find(text) != std::string::npos;
    return n;
  }
  std::vector<Line> lines;
};

class Watchdog : public ::testing::Test {
 protected:
  // Ports "A" and "B"; their loops' counters are `progress`.
  LoopWatchdog make() {
    return LoopWatchdog({"A", "B"}, kInterval, now, progress, Logger(log, "systemd"));
  }

  // Runs the notifier's ticks until `until`; before each tick every loop in
  // `advancing` goes round once. The times WATCHDOG=1 was sent.
  std::vector<TimePoint> run(LoopWatchdog& dog, TimePoint until, std::vector<bool> advancing) {
    std::vector<TimePoint> fed;
    while (now < until) {
      now += kTick;
      for (std::size_t i = 0; i < progress.size(); ++i) progress[i] += advancing[i] ? 1u : 0u;
      if (dog.check(now, progress)) fed.push_back(now);
    }
    return fed;
  }
  static std::vector<TimePoint> every_interval(TimePoint from, TimePoint to) {
    std::vector<TimePoint> v;
    for (TimePoint t = from; t <= to; t += kInterval) v.push_back(t);
    return v;
  }

  TimePoint now = kStart;
  std::vector<std::uint64_t> progress{100, 7};
  RecordingLog log;
};

TEST_F(Watchdog, EveryLoopAdvancingIsFedOncePerHalfWatchdogPeriod) {
  LoopWatchdog dog = make();
  EXPECT_EQ(dog.next_check(), kStart + kInterval);
  const auto fed = run(dog, kStart + seconds(30), {true, true});
  EXPECT_EQ(fed, every_interval(kStart + seconds(5), kStart + seconds(30)));
  EXPECT_TRUE(log.lines.empty());
  EXPECT_FALSE(dog.stalled(0));
  EXPECT_FALSE(dog.stalled(1));
}

// A loop that goes round only once per status period (1 s, idle) is alive.
TEST_F(Watchdog, ALoopThatAdvancesOnceBetweenChecksIsAlive) {
  LoopWatchdog dog = make();
  std::vector<TimePoint> fed;
  for (int s = 1; s <= 20; ++s) {
    now = kStart + seconds(s);
    progress[1] += s % 5 == 3 ? 1u : 0u;  // B: once per interval only
    ++progress[0];
    if (dog.check(now, progress)) fed.push_back(now);
  }
  EXPECT_EQ(fed, every_interval(kStart + seconds(5), kStart + seconds(20)));
}

TEST_F(Watchdog, OneStalledLoopStopsTheFeedingAndIsNamedOnce) {
  LoopWatchdog dog = make();
  EXPECT_EQ(run(dog, kStart + seconds(10), {true, true}).size(), 2u);
  // B stops going round just after the check at 10 s: the check at 15 s
  // sees it stalled, and nothing is fed from then on.
  EXPECT_TRUE(run(dog, kStart + seconds(60), {true, false}).empty());
  EXPECT_TRUE(dog.stalled(1));
  EXPECT_FALSE(dog.stalled(0));
  ASSERT_EQ(log.lines.size(), 1u);
  EXPECT_EQ(log.lines[0].level, LogLevel::kError);
  EXPECT_EQ(log.lines[0].message,
            "port B: loop stalled (no progress in 5000 ms): the watchdog is no longer fed, and "
            "systemd restarts the service when WatchdogSec= runs out");
  EXPECT_EQ(log.count(LogLevel::kError, "port A"), 0u);
}

TEST_F(Watchdog, ALoopThatAdvancesAgainIsFedForAgain) {
  LoopWatchdog dog = make();
  run(dog, kStart + seconds(10), {true, true});
  EXPECT_TRUE(run(dog, kStart + seconds(20), {true, false}).empty());
  // B goes round again at 20.25 s: fed at the next check, and on.
  EXPECT_EQ(run(dog, kStart + seconds(35), {true, true}),
            every_interval(kStart + seconds(25), kStart + seconds(35)));
  EXPECT_FALSE(dog.stalled(1));
  EXPECT_EQ(log.count(LogLevel::kError, "port B: loop stalled"), 1u);
  // Stalled since the check at 10 s; seen going round at the one at 25 s.
  EXPECT_EQ(
      log.count(LogLevel::kWarn, "port B: loop advances again, after 15000 ms without progress"),
      1u);
  EXPECT_EQ(log.lines.size(), 2u);

  // A second stall is a second episode: said again.
  EXPECT_TRUE(run(dog, kStart + seconds(45), {false, true}).empty());
  EXPECT_EQ(log.count(LogLevel::kError, "port A: loop stalled"), 1u);
}

TEST_F(Watchdog, BothStalledThenOnlyOneBackIsStillNotFed) {
  LoopWatchdog dog = make();
  run(dog, kStart + seconds(5), {true, true});
  EXPECT_TRUE(run(dog, kStart + seconds(10), {false, false}).empty());
  EXPECT_TRUE(run(dog, kStart + seconds(20), {true, false}).empty());
  EXPECT_FALSE(dog.stalled(0));
  EXPECT_TRUE(dog.stalled(1));
  EXPECT_EQ(run(dog, kStart + seconds(25), {true, true}),
            std::vector<TimePoint>{kStart + seconds(25)});
}

TEST_F(Watchdog, NothingIsDecidedBeforeTheCheckIsDue) {
  LoopWatchdog dog = make();
  now = kStart + kInterval - milliseconds(1);
  EXPECT_FALSE(dog.check(now, progress));  // no loop advanced, but not due yet
  EXPECT_FALSE(dog.stalled(0));
  EXPECT_TRUE(log.lines.empty());
  ++progress[0];
  ++progress[1];
  EXPECT_TRUE(dog.check(kStart + kInterval, progress));
}

// A notifier woken late (a loaded machine) checks once, not once per
// interval missed, and keeps its cadence from there.
TEST_F(Watchdog, ALateCheckIsOneCheckAndTheCadenceRestartsFromIt) {
  LoopWatchdog dog = make();
  ++progress[0];
  ++progress[1];
  now = kStart + seconds(17);
  EXPECT_TRUE(dog.check(now, progress));
  EXPECT_EQ(dog.next_check(), kStart + seconds(22));
  EXPECT_FALSE(dog.check(now, progress));
}

TEST(ServiceStatus, SaysNodesOnlineAndWhatIsWrongWithEachPort) {
  std::vector<PortSummary> ports{{"A", true, 8, 8, "", false}, {"B", false, 0, 1, "", false}};
  EXPECT_EQ(service_status(ports), "start-up checks: 8/9 nodes online (A 8/8, B 0/1)");
  ports[1].started_up = true;
  ports[1].problem = "interface can7 absent";
  EXPECT_EQ(service_status(ports), "8/9 nodes online (A 8/8, B 0/1: interface can7 absent)");
  ports[0].stalled = true;
  ports[1].stalled = true;
  EXPECT_EQ(service_status(ports),
            "8/9 nodes online (A 8/8: loop stalled, B 0/1: loop stalled; interface can7 absent)");
}

}  // namespace
}  // namespace dnbridge::daemon
