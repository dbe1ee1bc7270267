// Live reconfiguration of a port against simulated CDN127s, on a fake
// clock: a new scan list changes only the nodes it changes. An untouched
// node keeps every poll slot (its polls are counted across the change), a
// removed node gets its idle poll and is released, a changed node is
// released and configured again with its new settings, an added node comes
// online; a scan list the master refuses changes nothing.
#include <gtest/gtest.h>

#include <map>

#include "bridge/devicenet/wire/identifier.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::group2_id;
using devicenet::Group2Message;

// The poll requests (Group 2 message 5) and unconnected requests (message
// 6) the master sends each MAC, with their times and sizes.
struct WireLog {
  struct Poll {
    TimePoint at;
    std::size_t size;
  };
  std::map<unsigned, std::vector<Poll>> polls;
  std::map<unsigned, std::vector<TimePoint>> unconnected;
  std::map<unsigned, std::vector<std::uint8_t>> unconnected_services;

  void on(const sim::WireFrame& w) {
    for (unsigned m = 0; m <= devicenet::MacId::kMax; ++m) {
      if (w.frame.id == group2_id(mac(m), Group2Message::kMasterIoPoll)) {
        polls[m].push_back({w.end, w.frame.len});
      }
      if (w.frame.id == group2_id(mac(m), Group2Message::kUnconnectedExplicitRequest) &&
          w.frame.len >= 2) {
        unconnected[m].push_back(w.end);
        unconnected_services[m].push_back(w.frame.data[1] & 0x7F);
      }
    }
  }
  std::size_t polls_between(unsigned m, TimePoint from, TimePoint to) const {
    auto it = polls.find(m);
    if (it == polls.end()) return 0;
    std::size_t n = 0;
    for (const auto& p : it->second)
      if (p.at >= from && p.at < to) ++n;
    return n;
  }
  Duration longest_gap(unsigned m, TimePoint from, TimePoint to) const {
    Duration longest{};
    TimePoint last = from;
    for (const auto& p : polls.at(m)) {
      if (p.at < from || p.at >= to) continue;
      longest = std::max(longest, p.at - last);
      last = p.at;
    }
    return std::max(longest, to - last);
  }
};

constexpr std::uint8_t kRelease = 0x4C;

class LiveReconfigureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto config = rack_config({5, 6, 7, 8});
    port_ = config.port;
    pumps_ = config.pumps;
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->observe(events_);
    rack_->world().bus().set_tap([this](const sim::WireFrame& w) { wire_.on(w); });
    // A device the configuration does not have yet, for a node to add.
    rack_->add_device(sim::default_slave_options(mac(9)), now());
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->all_online(); }, seconds(30)));
    rack_->world().run_for(seconds(1));
  }

  sim::SimRack& rack() { return *rack_; }
  TimePoint now() { return rack_->now(); }
  rack::ScanListChange reconfigure(const std::vector<rack::PumpConfig>& pumps) {
    return rack_->port().reconfigure(port_, rack::PortNodes(pumps), now());
  }
  std::vector<rack::PumpConfig> without(unsigned m) const {
    std::vector<rack::PumpConfig> out;
    for (const auto& p : pumps_) {
      if (p.node.mac != mac(m)) out.push_back(p);
    }
    return out;
  }
  rack::PumpConfig& at(std::vector<rack::PumpConfig>& pumps, unsigned m) {
    for (auto& p : pumps) {
      if (p.node.mac == mac(m)) return p;
    }
    throw std::out_of_range("no such pump");
  }
  std::size_t transitions_since(unsigned m, TimePoint since) const {
    std::size_t n = 0;
    for (const auto& t : events_.of(mac(m)))
      if (t.at >= since) ++n;
    return n;
  }

  devicenet::ScannerConfig port_;
  std::vector<rack::PumpConfig> pumps_;
  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
  WireLog wire_;
};

TEST_F(LiveReconfigureTest, UntouchedNodesKeepEveryPollWhileOthersAreAddedRemovedAndChanged) {
  // 5 untouched, 6 renamed (applied in place), 7 removed, 8 with another
  // safe state (configured again), 9 added.
  auto next = without(7);
  at(next, 6).node.name = "pump six";
  at(next, 6).no_commander = rack::NoCommanderPolicy::kHoldLastOutputs;
  at(next, 8).safe_state.values.pump_fault = cdn127::DiscreteAction::kHold;
  next.push_back(pump(9));
  ASSERT_TRUE(rack().pumps().command(mac(5), cdn127::PumpOutputs{.pump_on = true}, now()).ok());
  ASSERT_TRUE(rack().pumps().command(mac(8), cdn127::PumpOutputs{.pump_on = true}, now()).ok());
  rack().world().run_for(seconds(1));
  const auto before = rack().scanner().node(mac(5))->counters();
  const auto before6 = rack().scanner().node(mac(6))->counters();

  const TimePoint reload = now();
  const auto change = reconfigure(next);
  EXPECT_EQ(change.added, std::vector<MacId>{mac(9)});
  EXPECT_EQ(change.removed, std::vector<MacId>{mac(7)});
  EXPECT_EQ(change.reconfigured, std::vector<MacId>{mac(8)});
  EXPECT_EQ(change.updated, std::vector<MacId>{mac(6)});
  EXPECT_EQ(change.unchanged, std::vector<MacId>{mac(5)});
  EXPECT_FALSE(change.timings_changed);
  // At once: no outputs for the removed node, nor for the changed one
  // before it is back; the renamed one keeps its state.
  EXPECT_EQ(rack().pumps().pump(mac(7)), nullptr);
  EXPECT_EQ(rack().scanner().node(mac(7)), nullptr);
  EXPECT_EQ(rack().scanner().set_outputs(mac(7), {}, now()).error(), Errc::kOutOfRange);
  EXPECT_EQ(rack().pumps().pump(mac(6))->name, "pump six");
  EXPECT_TRUE(rack().pumps().pump(mac(6))->online);
  EXPECT_FALSE(rack().pumps().pump(mac(8))->online);
  EXPECT_FALSE(rack().pumps().command(mac(8), cdn127::PumpOutputs{.pump_on = true}, now()).ok());

  ASSERT_TRUE(rack().world().run_until(
      [&] { return rack().all_online() && rack().scanner().nodes_leaving() == 0; }, seconds(30)));
  rack().world().run_for(seconds(5));
  const TimePoint end = now();

  // 5 and 6: every poll slot kept, every poll answered, nothing else.
  for (unsigned m : {5u, 6u}) {
    SCOPED_TRACE(m);
    EXPECT_EQ(transitions_since(m, reload), 0u);
    const Duration span = end - reload;
    const auto polls = wire_.polls_between(m, reload, end);
    const auto slots = static_cast<std::size_t>(span / milliseconds(100));
    EXPECT_GE(polls, slots);
    EXPECT_LE(polls, slots + 1);
    // A poll is at most the batch window ahead of its slot: no gap longer
    // than a period and that window.
    EXPECT_LE(wire_.longest_gap(m, reload, end), milliseconds(102));
  }
  const auto after = rack().scanner().node(mac(5))->counters();
  EXPECT_EQ(after.timeouts, before.timeouts);
  EXPECT_EQ(after.reconnects, before.reconnects);
  EXPECT_EQ(after.errors, before.errors);
  EXPECT_EQ(after.responses - before.responses, after.polls - before.polls);
  EXPECT_EQ(rack().scanner().node(mac(6))->counters().reconnects, before6.reconnects);
  // Its command stands.
  EXPECT_TRUE(rack().pumps().pump(mac(5))->outputs_requested.has_value());
  EXPECT_TRUE(rack().device(mac(5)).device().outputs().pump_on);

  // 7: one idle poll, then Release, then nothing more.
  const auto& polls7 = wire_.polls.at(7);
  auto first_after = std::find_if(polls7.begin(), polls7.end(),
                                  [&](const WireLog::Poll& p) { return p.at >= reload; });
  ASSERT_NE(first_after, polls7.end());
  EXPECT_EQ(first_after->size, 0u);  // idle
  EXPECT_EQ(std::next(first_after), polls7.end());
  ASSERT_FALSE(wire_.unconnected_services[7].empty());
  EXPECT_EQ(wire_.unconnected_services[7].back(), kRelease);
  EXPECT_GT(wire_.unconnected[7].back(), first_after->at);
  EXPECT_NE(rack().device(mac(7)).device().poll_state(), sim::ConnectionState::kEstablished);
  EXPECT_NE(rack().device(mac(7)).device().explicit_state(), sim::ConnectionState::kEstablished);

  // 8: one idle poll, then Release, before it is allocated again.
  const auto& polls8 = wire_.polls.at(8);
  auto idle8 = std::find_if(polls8.begin(), polls8.end(),
                            [&](const WireLog::Poll& p) { return p.at >= reload; });
  ASSERT_NE(idle8, polls8.end());
  EXPECT_EQ(idle8->size, 0u);
  std::vector<std::uint8_t> services8;
  for (std::size_t i = 0; i < wire_.unconnected.at(8).size(); ++i) {
    if (wire_.unconnected.at(8)[i] > idle8->at)
      services8.push_back(wire_.unconnected_services[8][i]);
  }
  ASSERT_GE(services8.size(), 2u);
  EXPECT_EQ(services8.front(), kRelease);
  EXPECT_NE(services8.back(), kRelease);  // allocated again
  // 8: released, configured again with the new safe state, idle until a
  // new command.
  const auto* eight = rack().pumps().pump(mac(8));
  ASSERT_TRUE(eight->safe_state.has_value());
  EXPECT_EQ(eight->safe_state->pump_fault, cdn127::DiscreteAction::kHold);
  EXPECT_FALSE(eight->outputs_requested.has_value());
  EXPECT_EQ(eight->idle_cause, rack::IdleCause::kReconfigured);
  EXPECT_FALSE(rack().device(mac(8)).device().outputs().pump_on);
  EXPECT_TRUE(rack().pumps().command(mac(8), cdn127::PumpOutputs{.pump_on = true}, now()).ok());

  // 9: online, never configured before.
  EXPECT_TRUE(rack().pumps().pump(mac(9))->online);
}

TEST_F(LiveReconfigureTest, AScanListTheMasterRefusesChangesNothing) {
  auto next = without(7);
  next.push_back(pump(9));
  next.back().node.poll_period = Duration::zero();  // refused by the master
  const TimePoint reload = now();
  EXPECT_THROW(reconfigure(next), std::invalid_argument);
  auto at_master = pumps_;
  at_master.push_back(pump(0));  // the master's own MAC
  EXPECT_THROW(reconfigure(at_master), std::invalid_argument);
  rack().world().run_for(seconds(2));
  EXPECT_EQ(rack().pumps().pumps().size(), 4u);
  EXPECT_NE(rack().scanner().node(mac(7)), nullptr);
  EXPECT_EQ(rack().scanner().node(mac(9)), nullptr);
  for (unsigned m : {5u, 6u, 7u, 8u}) EXPECT_EQ(transitions_since(m, reload), 0u) << m;
  // The same scan list again is no change at all.
  const auto same = reconfigure(pumps_);
  EXPECT_FALSE(same.any());
  EXPECT_EQ(same.unchanged.size(), 4u);
}

TEST_F(LiveReconfigureTest, TheSameMacReaddedWhileLeavingStartsOnceReleased) {
  // 7 out and back with other settings in one change is a re-configuration;
  // out in one change and back in the next, before its release, it waits.
  const TimePoint reload = now();
  reconfigure(without(7));
  ASSERT_EQ(rack().scanner().nodes_leaving(), 1u);
  auto back = pumps_;
  at(back, 7).node.poll_period = milliseconds(200);
  at(back, 7).node.expected_packet_rate = milliseconds(800);
  const auto change = reconfigure(back);
  EXPECT_EQ(change.added, std::vector<MacId>{mac(7)});
  ASSERT_TRUE(rack().world().run_until(
      [&] { return rack().all_online() && rack().scanner().nodes_leaving() == 0; }, seconds(30)));
  // Released (Release after the reload) before it was allocated again.
  const auto& services = wire_.unconnected_services.at(7);
  const auto& times = wire_.unconnected.at(7);
  std::vector<std::uint8_t> since;
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (times[i] >= reload) since.push_back(services[i]);
  }
  ASSERT_GE(since.size(), 2u);
  EXPECT_EQ(since.front(), kRelease);
  EXPECT_NE(since.back(), kRelease);
  EXPECT_EQ(rack().scanner().node(mac(7))->config().poll_period, milliseconds(200));
  rack().world().run_for(seconds(2));
  const TimePoint t = now();
  rack().world().run_for(seconds(2));
  EXPECT_NEAR(static_cast<double>(wire_.polls_between(7, t, now())), 10.0, 1.0);
}

TEST_F(LiveReconfigureTest, ThePortsTimingsReachEveryNodeWithoutTouchingIt) {
  devicenet::ScannerConfig slower = port_;
  slower.poll_response_timeout = milliseconds(40);
  slower.explicit_messaging.response_timeout = milliseconds(1500);
  slower.fault_recheck = seconds(20);
  port_ = slower;
  const TimePoint reload = now();
  const auto change = reconfigure(pumps_);
  EXPECT_TRUE(change.timings_changed);
  EXPECT_EQ(change.unchanged.size(), 4u);
  EXPECT_EQ(rack().scanner().config().poll_response_timeout, milliseconds(40));
  for (unsigned m : {5u, 6u, 7u, 8u}) {
    EXPECT_EQ(rack().scanner().node(mac(m))->explicit_response_timeout(), milliseconds(1500));
  }
  rack().world().run_for(seconds(3));
  for (unsigned m : {5u, 6u, 7u, 8u}) EXPECT_EQ(transitions_since(m, reload), 0u) << m;
}

// The bus lost while a node is being taken out (bus-off recovered at once):
// once the master is back on the bus, that node is released all the same,
// not left to its device's watchdog; a node put back at its MAC starts
// after that.
TEST_F(LiveReconfigureTest, ANodeTakenOutIsReleasedOnceTheMasterIsBackAfterABusLoss) {
  auto without7 = without(7);
  reconfigure(without7);
  ASSERT_EQ(rack().scanner().nodes_leaving(), 1u);
  const TimePoint lost = now();
  rack().scanner().recheck_mac("bus-off recovered", now());
  auto back = pumps_;
  at(back, 7).node.poll_period = milliseconds(200);
  at(back, 7).node.expected_packet_rate = milliseconds(800);
  EXPECT_EQ(reconfigure(back).added, std::vector<MacId>{mac(7)});
  ASSERT_TRUE(rack().world().run_until(
      [&] { return rack().all_online() && rack().scanner().nodes_leaving() == 0; }, seconds(30)));
  // After the loss: a Release first, then the new node's Allocate.
  std::vector<std::uint8_t> since;
  for (std::size_t i = 0; i < wire_.unconnected.at(7).size(); ++i) {
    if (wire_.unconnected.at(7)[i] > lost) since.push_back(wire_.unconnected_services[7][i]);
  }
  ASSERT_GE(since.size(), 2u);
  EXPECT_EQ(since.front(), kRelease);
  EXPECT_NE(since.back(), kRelease);
  EXPECT_EQ(rack().scanner().node(mac(7))->config().poll_period, milliseconds(200));
}

// A MAC's events come from one node at a time, whatever the changes: a node
// put back while its MAC's previous one is released, then taken out again
// before it started, goes without a word; one put back when the port stops
// stops after the one released.
TEST_F(LiveReconfigureTest, AMacsEventsComeFromOneNodeAtATime) {
  // Each transition starts where the last one ended, or, after a node
  // stopped, a node put back starts anew (absent).
  const auto continuous = [&](unsigned m) {
    const auto t = events_.of(mac(m));
    for (std::size_t i = 1; i < t.size(); ++i) {
      const bool anew = t[i - 1].to == NodeState::kStopped && t[i].from == NodeState::kAbsent;
      if (t[i].from != t[i - 1].to && !anew) return false;
    }
    return true;
  };
  auto back = pumps_;
  at(back, 7).node.poll_period = milliseconds(200);
  at(back, 7).node.expected_packet_rate = milliseconds(800);
  reconfigure(without(7));
  reconfigure(back);
  reconfigure(without(7));  // the one put back had not started
  EXPECT_EQ(rack().scanner().nodes_leaving(), 1u);
  ASSERT_TRUE(
      rack().world().run_until([&] { return rack().scanner().nodes_leaving() == 0; }, seconds(10)));
  EXPECT_EQ(rack().scanner().node(mac(7)), nullptr);
  EXPECT_EQ(events_.of(mac(7)).back().to, NodeState::kStopped);
  reconfigure(back);
  ASSERT_TRUE(rack().world().run_until([&] { return rack().all_online(); }, seconds(10)));
  // Put back again, then the port stops while the previous node is released.
  reconfigure(without(7));
  reconfigure(pumps_);
  rack().scanner().stop(now());
  ASSERT_TRUE(rack().world().run_until([&] { return rack().scanner().stopped(); }, seconds(10)));
  EXPECT_EQ(rack().scanner().state(), devicenet::PortState::kStopped);
  EXPECT_EQ(rack().scanner().node(mac(7))->state(), NodeState::kStopped);
  for (unsigned m : {5u, 6u, 7u, 8u}) EXPECT_TRUE(continuous(m)) << m;
  // 7: online, released, [the one put back, never started, gone without a
  // word], put back and online, released, the one put back stopped after.
  std::vector<NodeState> ends;
  for (const auto& t : events_.of(mac(7))) {
    if (t.to == NodeState::kStopped || t.to == NodeState::kOnline) ends.push_back(t.to);
  }
  EXPECT_EQ(ends,
            (std::vector<NodeState>{NodeState::kOnline, NodeState::kStopped, NodeState::kOnline,
                                    NodeState::kStopped, NodeState::kStopped}));
}

// A pump held for a commander that has gone keeps its outputs only as long
// as its policy says so: a reload to the idle policy idles it at once.
TEST_F(LiveReconfigureTest, OutputsHeldForAGoneCommanderGoIdleWhenThePolicyBecomesIdle) {
  auto hold = pumps_;
  at(hold, 6).no_commander = rack::NoCommanderPolicy::kHoldLastOutputs;
  EXPECT_EQ(reconfigure(hold).updated, std::vector<MacId>{mac(6)});
  ASSERT_TRUE(rack().pumps().command(mac(6), cdn127::PumpOutputs{.pump_on = true}, now()).ok());
  ASSERT_TRUE(rack().pumps().command(mac(5), cdn127::PumpOutputs{.pump_on = true}, now()).ok());
  rack().world().run_for(milliseconds(300));
  ASSERT_TRUE(rack().pumps().release_command(mac(6), now()).ok());  // its commander left
  rack().world().run_for(milliseconds(300));
  ASSERT_TRUE(rack().device(mac(6)).device().outputs().pump_on);  // held, as configured

  const TimePoint reload = now();
  EXPECT_EQ(reconfigure(pumps_).updated, std::vector<MacId>{mac(6)});
  rack().world().run_for(milliseconds(300));
  EXPECT_FALSE(rack().device(mac(6)).device().outputs().pump_on);
  EXPECT_FALSE(rack().pumps().pump(mac(6))->outputs_requested.has_value());
  EXPECT_EQ(rack().pumps().pump(mac(6))->idle_cause, rack::IdleCause::kNoCommander);
  EXPECT_EQ(transitions_since(6, reload), 0u);  // idle polls, the node untouched
  // A pump whose commander is there keeps its outputs.
  EXPECT_TRUE(rack().device(mac(5)).device().outputs().pump_on);
}

}  // namespace
}  // namespace dnbridge::test
