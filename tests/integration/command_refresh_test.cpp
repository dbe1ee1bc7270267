// The command refresh (command_refresh_ms) in the rack model, on the
// simulated bus with its fake clock: a command not written again within the
// node's refresh is no longer in force, and one written in time never
// lapses. The port loop calls expire_silent_commanders at
// next_refresh_deadline; here the test does, as often as the loop would.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "bridge/rack/pump_rack.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;

constexpr auto kRefresh = milliseconds(500);
constexpr auto kPoll = milliseconds(100);  // rack_fixture's pumps

class CommandRefresh : public ::testing::Test {
 protected:
  void start(rack::NoCommanderPolicy policy = rack::NoCommanderPolicy::kIdle) {
    auto config = rack_config({1, 2});
    config.pumps[0].command_refresh = kRefresh;
    config.pumps[0].no_commander = policy;
    rack_ = std::make_unique<sim::SimRack>(config);
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->all_online(); }, seconds(20)));
  }
  sim::SimRack& rack() { return *rack_; }
  rack::PumpRack& pumps() { return rack_->pumps(); }
  const rack::PumpView& view() { return *pumps().pump(mac(1)); }
  bool device_on() { return rack().device(mac(1)).device().outputs().pump_on; }

  Status command(std::string_view issuer = "supervisor") {
    cdn127::PumpOutputs on;
    on.pump_on = true;
    return pumps().command(mac(1), on, issuer, rack().now());
  }
  // Runs the world for `d`, expiring silent commanders whenever the loop
  // would: at their deadline.
  std::vector<rack::PumpRack::Silenced> run_for(Duration d) {
    std::vector<rack::PumpRack::Silenced> silenced;
    const TimePoint end = rack().now() + d;
    while (rack().now() < end) {
      rack().world().run_until(std::min(end, pumps().next_refresh_deadline()));
      for (auto& s : pumps().expire_silent_commanders(rack().now())) silenced.push_back(s);
    }
    return silenced;
  }

  std::unique_ptr<sim::SimRack> rack_;
};

TEST_F(CommandRefresh, ACommandWrittenWithinTheRefreshNeverLapsesThroughAnHour) {
  ASSERT_NO_FATAL_FAILURE(start());
  ASSERT_TRUE(command().ok());
  ASSERT_TRUE(run_for(kPoll * 2).empty());
  ASSERT_TRUE(device_on());
  ASSERT_TRUE(command().ok());
  // Written again after anything from a tenth to just under the refresh:
  // late writes, early writes, never one past it.
  std::mt19937 random(36);
  std::uniform_int_distribution<int> gap_ms(50, 499);
  const TimePoint end = rack().now() + std::chrono::hours(1);
  std::uint64_t writes = 0;
  Duration longest{};
  while (rack().now() < end) {
    const Duration gap = milliseconds(gap_ms(random));
    longest = std::max(longest, gap);
    const auto silenced = run_for(gap);
    ASSERT_TRUE(silenced.empty()) << "the command lapsed after a gap of "
                                  << std::chrono::duration_cast<milliseconds>(gap).count()
                                  << " ms, with a refresh of 500 ms";
    ASSERT_FALSE(view().outputs_idle) << "the outputs went idle under a refreshing commander";
    ASSERT_TRUE(device_on());
    ASSERT_TRUE(command().ok());
    ++writes;
  }
  EXPECT_GT(writes, 10000u);
  EXPECT_EQ(longest, milliseconds(499));
  EXPECT_EQ(view().commanded_by, "supervisor");
}

TEST_F(CommandRefresh, ACommandNotWrittenAgainLapsesAtTheRefreshAndTheDeviceGoesIdle) {
  ASSERT_NO_FATAL_FAILURE(start());
  ASSERT_TRUE(command("quiet").ok());
  const TimePoint written = rack().now();
  EXPECT_EQ(pumps().next_refresh_deadline(), written + kRefresh);
  const auto silenced = run_for(kRefresh + kPoll * 2);
  ASSERT_EQ(silenced.size(), 1u);
  EXPECT_EQ(silenced[0].mac, mac(1));
  EXPECT_EQ(silenced[0].issuer, "quiet");
  EXPECT_TRUE(view().outputs_idle);
  EXPECT_EQ(view().idle_reason(), "idle: commander silent for 500 ms");
  EXPECT_TRUE(view().commanded_by.empty());
  // Within the refresh and one poll, the device applies its idle state.
  EXPECT_FALSE(device_on());
  // Nothing left to expire; the other node (no refresh) was never concerned.
  EXPECT_EQ(pumps().next_refresh_deadline(), kNever);
  // A fresh command is in force again.
  ASSERT_TRUE(command("quiet").ok());
  rack().world().run_for(kPoll * 2);
  EXPECT_TRUE(device_on());
}

TEST_F(CommandRefresh, ANodeWithoutRefreshKeepsItsCommandForAnyTime) {
  ASSERT_NO_FATAL_FAILURE(start());
  cdn127::PumpOutputs on;
  on.pump_on = true;
  ASSERT_TRUE(pumps().command(mac(2), on, "once", rack().now()).ok());
  EXPECT_EQ(pumps().next_refresh_deadline(), kNever);
  EXPECT_TRUE(run_for(std::chrono::minutes(10)).empty());
  EXPECT_TRUE(rack().device(mac(2)).device().outputs().pump_on);
}

// A reload that changes a node's refresh while a command is in force: the
// command must still be written again in time, through the readers of the
// new refresh, and a commander that does so keeps its pump.
TEST_F(CommandRefresh, ARefreshTurnedOffByAReloadStillLapsesACommandNotWrittenAgain) {
  ASSERT_NO_FATAL_FAILURE(start());
  ASSERT_TRUE(command().ok());
  const TimePoint lapse = rack().now() + kRefresh;
  rack().world().run_for(milliseconds(100));
  auto off = rack_config({1, 2}).pumps[0];
  off.command_refresh = Duration::zero();
  pumps().update(off, rack().now());
  EXPECT_EQ(pumps().next_refresh_deadline(), lapse);
  const auto silenced = run_for(kRefresh);
  ASSERT_EQ(silenced.size(), 1u) << "a command the commander never wrote again stayed in force";
  EXPECT_FALSE(device_on());
  // Written again, it holds without a refresh.
  ASSERT_TRUE(command().ok());
  EXPECT_EQ(pumps().next_refresh_deadline(), kNever);
  EXPECT_TRUE(run_for(seconds(10)).empty());
  EXPECT_TRUE(device_on());
}

TEST_F(CommandRefresh, ARefreshTurnedOnByAReloadCountsFromTheReload) {
  auto config = rack_config({1});
  rack_ = std::make_unique<sim::SimRack>(config);
  rack_->start();
  ASSERT_TRUE(rack().world().run_until([&] { return rack().all_online(); }, seconds(20)));
  ASSERT_TRUE(command().ok());
  rack().world().run_for(seconds(5));
  auto on = config.pumps[0];
  on.command_refresh = kRefresh;
  pumps().update(on, rack().now());
  EXPECT_EQ(pumps().next_refresh_deadline(), rack().now() + kRefresh);
  ASSERT_TRUE(run_for(kRefresh - milliseconds(10)).empty());
  ASSERT_TRUE(command().ok());  // in time
  EXPECT_TRUE(run_for(kRefresh - milliseconds(10)).empty());
  EXPECT_TRUE(device_on());
  EXPECT_EQ(run_for(milliseconds(20)).size(), 1u);
}

TEST_F(CommandRefresh, UnderTheHoldPolicyASilentCommandersOutputsAreHeld) {
  ASSERT_NO_FATAL_FAILURE(start(rack::NoCommanderPolicy::kHoldLastOutputs));
  ASSERT_TRUE(command().ok());
  const auto silenced = run_for(kRefresh + kPoll * 2);
  ASSERT_EQ(silenced.size(), 1u);
  EXPECT_FALSE(view().outputs_idle);
  EXPECT_TRUE(device_on());
  // Held once: not expired again and again.
  EXPECT_EQ(pumps().next_refresh_deadline(), kNever);
  EXPECT_TRUE(run_for(seconds(5)).empty());
}

}  // namespace
}  // namespace dnbridge::test
