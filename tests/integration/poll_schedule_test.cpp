// The master's poll schedule against simulated CDN127s on an ideal bus (a
// frame is on the wire the instant it is sent), on a fake clock: every node
// at its slot, or ahead of it within the batching window, never late.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "adapters/sim/world/sim_rack.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "integration/rack_fixture.hpp"

namespace dnbridge::test {
namespace {

using devicenet::Group2Message;
using devicenet::MessageGroup;

class PollSchedule : public ::testing::Test {
 protected:
  void build(std::vector<unsigned> macs, Duration period, Duration window) {
    sim::SimRackConfig c = rack_config(std::move(macs));
    c.bus.bitrate = 0;  // ideal: the tap sees each poll at the time it was sent
    c.port.poll_batch_window = window;
    for (auto& p : c.pumps) p.node.poll_period = period;
    rack_ = std::make_unique<sim::SimRack>(std::move(c));
    rack_->world().bus().set_tap([this, period](const sim::WireFrame& w) {
      const auto id = devicenet::decode_identifier(w.frame.id);
      if (recording_ && id && id->group == MessageGroup::k2 &&
          id->message_id == static_cast<std::uint8_t>(Group2Message::kMasterIoPoll)) {
        polls_[id->mac.value()].push_back(w.end);
        // The slot this poll served: the one before the node's next.
        slots_[id->mac.value()].push_back(rack_->scanner().node(id->mac)->next_poll() - period);
      }
    });
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->all_online(); }, seconds(30)));
  }

  // Polls while the rack runs for `span`, per MAC.
  void record(Duration span) {
    recording_ = true;
    rack_->world().run_for(span);
    recording_ = false;
  }

  std::size_t distinct_poll_times() const {
    std::set<TimePoint> times;
    for (const auto& [mac, at] : polls_) times.insert(at.begin(), at.end());
    return times.size();
  }

  // Shortest and longest gap between two polls of one node, over all nodes.
  std::pair<Duration, Duration> gap_range() const {
    Duration shortest = Duration::max();
    Duration longest = Duration::zero();
    for (const auto& [mac, at] : polls_) {
      for (std::size_t i = 1; i < at.size(); ++i) {
        shortest = std::min(shortest, at[i] - at[i - 1]);
        longest = std::max(longest, at[i] - at[i - 1]);
      }
    }
    return {shortest, longest};
  }

  // Every poll at its slot or ahead of it by at most `window`.
  void expect_within_slots(Duration window) const {
    for (const auto& [mac, at] : polls_) {
      const auto& slot = slots_.at(mac);
      for (std::size_t i = 0; i < at.size(); ++i) {
        EXPECT_LE(at[i], slot[i]) << "MAC " << mac << " poll " << i << " late";
        EXPECT_GE(at[i], slot[i] - window) << "MAC " << mac << " poll " << i << " too early";
      }
    }
  }

  std::unique_ptr<sim::SimRack> rack_;
  bool recording_ = false;
  std::map<unsigned, std::vector<TimePoint>> polls_;
  std::map<unsigned, std::vector<TimePoint>> slots_;
};

TEST_F(PollSchedule, WithoutBatchingEveryNodeIsPolledExactlyAtItsSlot) {
  build({1, 2, 3, 4, 5, 6, 7, 8}, milliseconds(10), Duration::zero());
  record(seconds(1));
  ASSERT_EQ(polls_.size(), 8u);
  for (const auto& [mac, at] : polls_) EXPECT_EQ(at.size(), 100u) << "MAC " << mac;
  const auto [shortest, longest] = gap_range();
  EXPECT_EQ(shortest, milliseconds(10));
  EXPECT_EQ(longest, milliseconds(10));
  // Staggered: no two nodes share an instant.
  EXPECT_EQ(distinct_poll_times(), 800u);
  expect_within_slots(Duration::zero());
}

TEST_F(PollSchedule, PollsDueWithinTheWindowGoOutTogetherNeverLate) {
  // Slots 1.25 ms apart; a 2 ms window serves two slots per wake-up.
  build({1, 2, 3, 4, 5, 6, 7, 8}, milliseconds(10), milliseconds(2));
  record(seconds(1));
  ASSERT_EQ(polls_.size(), 8u);
  for (const auto& [mac, at] : polls_) {
    // The slots are unchanged: as many polls as without batching.
    EXPECT_GE(at.size(), 99u) << "MAC " << mac;
    EXPECT_LE(at.size(), 101u) << "MAC " << mac;
  }
  // Early by at most the window, never late: consecutive polls of a node are
  // a period apart, give or take the window.
  const auto [shortest, longest] = gap_range();
  EXPECT_GE(shortest, milliseconds(8));
  EXPECT_LE(longest, milliseconds(12));
  EXPECT_LE(distinct_poll_times(), 400u);
  expect_within_slots(milliseconds(2));
}

TEST_F(PollSchedule, AWindowLongerThanAQuarterPeriodIsCutToIt) {
  // 4 ms period: the 2 ms window is cut to 1 ms, so no node is polled more
  // than 1 ms ahead of its slot.
  build({1, 2, 3, 4}, milliseconds(4), milliseconds(2));
  record(seconds(1));
  ASSERT_EQ(polls_.size(), 4u);
  for (const auto& [mac, at] : polls_) {
    EXPECT_GE(at.size(), 249u) << "MAC " << mac;
    EXPECT_LE(at.size(), 251u) << "MAC " << mac;
  }
  const auto [shortest, longest] = gap_range();
  EXPECT_GE(shortest, milliseconds(3));
  EXPECT_LE(longest, milliseconds(5));
  EXPECT_LT(distinct_poll_times(), 1000u);
  expect_within_slots(milliseconds(1));
}

TEST_F(PollSchedule, AnUnansweredPollLeavesTheNextSlotOnTime) {
  // Node 2's slots lie 1.25 ms after node 1's: batches of (1, 2) go out at
  // node 1's slot, node 2's poll 1.25 ms early. A command sent just after
  // such a batch is polled at once; that poll's response is lost, and it is
  // given up a period later, after the next batch has gone out. Node 2's slot
  // in that batch is then served at its own time, not skipped.
  build({1, 2, 3, 4, 5, 6, 7, 8}, milliseconds(10), milliseconds(2));
  record(milliseconds(100));
  const TimePoint batch = polls_.at(2).back() + milliseconds(10);
  ASSERT_LT(rack_->now(), batch);
  rack_->world().run_for(batch + microseconds(300) - rack_->now());
  ASSERT_EQ(rack_->now(), batch + microseconds(300));
  ASSERT_EQ(rack_->scanner().node(mac(2))->counters().polls,
            rack_->scanner().node(mac(2))->counters().responses)
      << "node 2's batch poll is answered before the command";
  auto lose_one = sim::FaultRule::drop(
      devicenet::group1_id(devicenet::Group1Message::kSlavePollResponse, mac(2)));
  lose_one.count = 1;
  rack_->world().bus().faults().add(lose_one);
  polls_.clear();
  slots_.clear();
  recording_ = true;
  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  ASSERT_TRUE(rack_->pumps().command(mac(2), out, rack_->now()).ok());
  rack_->world().run_for(milliseconds(50));
  recording_ = false;

  const auto& at = polls_.at(2);
  ASSERT_GE(at.size(), 5u);
  EXPECT_EQ(at[0], batch + microseconds(300)) << "the command's poll goes out at once";
  for (std::size_t i = 1; i < at.size(); ++i) {
    EXPECT_LE(at[i] - at[i - 1], milliseconds(12)) << "gap before poll " << i;
  }
  EXPECT_EQ(rack_->scanner().node(mac(2))->counters().timeouts, 1u);
}

}  // namespace
}  // namespace dnbridge::test
