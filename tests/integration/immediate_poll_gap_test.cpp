// Polls sent early because a pump's outputs changed, against simulated
// CDN127s on the in-process bus, on a fake clock: at least
// NodeConfig::immediate_poll_min_gap apart, so that a flood of changing
// commands cannot take the bus, while a command that comes alone is still
// polled at once and none waits past the node's next slot.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <vector>

#include "adapters/sim/world/sim_rack.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "integration/rack_fixture.hpp"

namespace dnbridge::test {
namespace {

using devicenet::Group2Message;
using devicenet::MessageGroup;
using profiles::cdn127::PumpOutputs;

constexpr Duration kGap = milliseconds(10);
constexpr Duration kPeriod = milliseconds(100);  // rack_config's poll period

// Outputs that differ for every `n`.
PumpOutputs outputs(unsigned n) {
  PumpOutputs out;
  out.analog_out_raw = static_cast<std::uint16_t>(1 + n % 4000);
  return out;
}

class ImmediatePollGap : public ::testing::Test {
 protected:
  struct Poll {
    TimePoint at;
    std::size_t len;  // 0: an idle poll
  };

  // A pump at MAC 1, 2, ... for each gap, polled every 100 ms. Bit rate 0:
  // an ideal bus, where the tap sees a poll at the time it was sent.
  void build(std::vector<Duration> gaps, std::uint32_t bitrate = 0) {
    std::vector<unsigned> macs;
    for (unsigned m = 1; m <= gaps.size(); ++m) macs.push_back(m);
    sim::SimRackConfig c = rack_config(macs);
    c.bus.bitrate = bitrate;
    for (std::size_t i = 0; i < gaps.size(); ++i) c.pumps[i].node.immediate_poll_min_gap = gaps[i];
    rack_ = std::make_unique<sim::SimRack>(std::move(c));
    rack_->world().bus().set_tap([this](const sim::WireFrame& w) {
      const auto id = devicenet::decode_identifier(w.frame.id);
      if (id && id->group == MessageGroup::k2 &&
          id->message_id == static_cast<std::uint8_t>(Group2Message::kMasterIoPoll)) {
        polls_[id->mac.value()].push_back({w.end, w.frame.len});
      }
    });
    rack_->start();
    ASSERT_TRUE(rack_->world().run_until([&] { return rack_->all_online(); }, seconds(30)));
    for (unsigned m : macs) ASSERT_EQ(node(m).config().poll_period, kPeriod);
  }

  TimePoint now() const { return rack_->now(); }
  const devicenet::Node& node(unsigned m) { return *rack_->scanner().node(mac(m)); }
  const PumpOutputs& device_outputs(unsigned m) { return rack_->device(mac(m)).device().outputs(); }
  void command(unsigned m, const PumpOutputs& out) {
    ASSERT_TRUE(rack_->pumps().command(mac(m), out, now()).ok());
  }
  void run_to(TimePoint t) { rack_->world().run_until(t); }

  // Runs until no node polled within `margin` and none is due within it: what
  // follows is the test's alone.
  void run_to_quiet_moment(Duration margin = milliseconds(20)) {
    for (int i = 0; i < 1000; ++i) {
      bool quiet = true;
      for (const auto& [m, p] : polls_) {
        if (!p.empty() && now() - p.back().at < margin) quiet = false;
        if (node(m).next_poll() - now() < margin) quiet = false;
      }
      if (quiet) return;
      rack_->world().run_for(milliseconds(1));
    }
    FAIL() << "no quiet moment";
  }

  // The polls of MAC `m` sent at or after `from`.
  std::vector<Poll> polls_since(unsigned m, TimePoint from) const {
    std::vector<Poll> out;
    for (const Poll& p : polls_.at(m)) {
      if (p.at >= from) out.push_back(p);
    }
    return out;
  }

  std::unique_ptr<sim::SimRack> rack_;
  std::map<unsigned, std::vector<Poll>> polls_;
};

TEST_F(ImmediatePollGap, AFloodOfChangesIsPolledAtMostOncePerGap) {
  // The 500 kbit/s bus: without the gap, every response to a poll with
  // outputs changed meanwhile is followed by the next poll at once, about
  // 2 600 polls a second for one node, the bus all but full.
  build({kGap}, can::kBitrate500k);
  const TimePoint start = now();
  const auto polls_before = node(1).counters().polls;
  unsigned n = 0;
  for (; now() - start < seconds(1); ++n) {
    command(1, outputs(n));
    rack_->world().run_for(microseconds(100));
  }
  EXPECT_EQ(n, 10'000u);
  const auto polls = node(1).counters().polls - polls_before;
  // One poll per gap for the changes, and the node's slots as ever.
  const auto per_gap = static_cast<std::uint64_t>(seconds(1) / kGap);
  const auto slots = static_cast<std::uint64_t>(seconds(1) / kPeriod);
  EXPECT_LE(polls, per_gap + slots + 1);
  EXPECT_GE(polls, per_gap - 1) << "the changes are still carried every gap";
  // No change waits longer than the gap (and a response) for its poll.
  const auto during = polls_since(1, start);
  for (std::size_t i = 1; i < during.size(); ++i) {
    EXPECT_LE(during[i].at - during[i - 1].at, kGap + milliseconds(1)) << "poll " << i;
  }
  // The last change is carried at the end of its gap.
  run_to(now() + kGap);
  EXPECT_EQ(device_outputs(1), outputs(n - 1));
  EXPECT_EQ(node(1).counters().timeouts, 0u);
  EXPECT_EQ(node(1).state(), NodeState::kOnline);
}

TEST_F(ImmediatePollGap, AChangeAfterAQuietPeriodIsPolledAtOnce) {
  build({kGap});
  run_to_quiet_moment();
  // A flood held to one poll per gap...
  const TimePoint flood = now();
  unsigned n = 0;
  for (; now() - flood < milliseconds(50); ++n) {
    command(1, outputs(n));
    rack_->world().run_for(microseconds(100));
  }
  ASSERT_LE(polls_since(1, flood).size(), 50 / 10 + 1u);
  // ...then nothing for a gap: the next change goes out the instant it is made.
  run_to(now() + kGap);
  const TimePoint t = now();
  command(1, outputs(n));
  run_to(t + microseconds(1));
  const auto after = polls_since(1, t);
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after[0].at, t);
  EXPECT_EQ(device_outputs(1), outputs(n));
}

TEST_F(ImmediatePollGap, ChangesWithinTheGapArePolledOnceWhenItEndsWithTheLatestOutputs) {
  build({kGap});
  run_to_quiet_moment();
  const TimePoint t0 = now();
  command(1, outputs(1));  // alone: polled at once
  run_to(t0 + milliseconds(1));
  command(1, outputs(2));
  run_to(t0 + milliseconds(4));
  command(1, outputs(3));
  run_to(t0 + milliseconds(7));
  command(1, outputs(4));
  run_to(t0 + kGap - Duration(1));
  ASSERT_EQ(polls_since(1, t0).size(), 1u) << "the changes are held to the end of the gap";
  EXPECT_EQ(device_outputs(1), outputs(1));
  run_to(t0 + kGap);
  auto polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 2u);
  EXPECT_EQ(polls[1].at, t0 + kGap) << "exactly at the last poll + the gap";
  EXPECT_EQ(device_outputs(1), outputs(4)) << "the latest outputs";

  // Idle (the commander gone) within the next gap: the same.
  run_to(t0 + kGap + milliseconds(1));
  ASSERT_TRUE(rack_->pumps().release_command(mac(1), now()).ok());
  run_to(t0 + 2 * kGap - Duration(1));
  EXPECT_EQ(polls_since(1, t0).size(), 2u);
  run_to(t0 + 2 * kGap + milliseconds(5));
  polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 3u);
  EXPECT_EQ(polls[2].at, t0 + 2 * kGap);
  EXPECT_EQ(polls[2].len, 0u) << "an idle poll";
  EXPECT_TRUE(node(1).applied_idle());
}

TEST_F(ImmediatePollGap, TheWakeUpTimeCoversTheDeferredPoll) {
  build({kGap});
  run_to_quiet_moment();
  const TimePoint t0 = now();
  command(1, outputs(1));
  run_to(t0 + milliseconds(2));
  command(1, outputs(2));
  // The port's loop sleeps until the scanner's next deadline: that is the
  // held-back poll, not the node's next slot.
  EXPECT_EQ(node(1).deadline(), t0 + kGap);
  EXPECT_EQ(rack_->scanner().next_deadline(), t0 + kGap);
  EXPECT_GT(node(1).next_poll(), t0 + kGap);
  run_to(t0 + kGap);
  const auto polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 2u);
  EXPECT_EQ(polls[1].at, t0 + kGap);
  EXPECT_GT(rack_->scanner().next_deadline(), t0 + kGap) << "nothing left due";
}

TEST_F(ImmediatePollGap, AChangeNeverWaitsPastTheNodesNextSlot) {
  build({milliseconds(60)});
  run_to_quiet_moment();
  const TimePoint slot = node(1).next_poll();
  run_to(slot - milliseconds(30));
  const TimePoint t0 = now();
  command(1, outputs(1));
  run_to(t0 + milliseconds(1));
  command(1, outputs(2));  // held to t0 + 60 ms, but the slot comes first
  run_to(slot);
  auto polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 2u);
  EXPECT_EQ(polls[1].at, slot);
  EXPECT_EQ(device_outputs(1), outputs(2)) << "the slot's poll carries the change";
  // Nothing more at the end of the gap: the next poll is the next slot.
  run_to(slot + kPeriod);
  polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 3u);
  EXPECT_EQ(polls[2].at, slot + kPeriod);
}

TEST_F(ImmediatePollGap, WithAGapOfZeroEveryChangeIsPolledAtOnceAsBefore) {
  // Two pumps given the same changes: MAC 1 without a gap, MAC 2 with one.
  build({Duration::zero(), kGap});
  run_to_quiet_moment();
  const TimePoint t0 = now();
  for (unsigned i = 0; i < 5; ++i) {
    run_to(t0 + milliseconds(i));
    command(1, outputs(i));
    command(2, outputs(i));
  }
  run_to(t0 + milliseconds(15));
  const auto none = polls_since(1, t0);
  ASSERT_EQ(none.size(), 5u);
  for (unsigned i = 0; i < 5; ++i) EXPECT_EQ(none[i].at, t0 + milliseconds(i)) << i;
  const auto gap = polls_since(2, t0);
  ASSERT_EQ(gap.size(), 2u);
  EXPECT_EQ(gap[0].at, t0);
  EXPECT_EQ(gap[1].at, t0 + kGap);
  EXPECT_EQ(device_outputs(1), outputs(4));
  EXPECT_EQ(device_outputs(2), outputs(4));
}

TEST_F(ImmediatePollGap, TheShutdownIdlePollIsNotHeldBackByTheGap) {
  build({kGap});
  run_to_quiet_moment();
  const TimePoint t0 = now();
  command(1, outputs(1));
  run_to(t0 + milliseconds(1));
  command(1, outputs(2));  // held back by the gap
  run_to(t0 + milliseconds(2));
  ASSERT_EQ(polls_since(1, t0).size(), 1u);
  rack_->scanner().stop(now());
  rack_->world().run_until([&] { return rack_->scanner().stopped(); }, seconds(1));
  ASSERT_TRUE(rack_->scanner().stopped());
  run_to(t0 + 5 * kGap);
  const auto polls = polls_since(1, t0);
  ASSERT_EQ(polls.size(), 2u) << "the idle poll, not the held-back change";
  EXPECT_EQ(polls[1].at, t0 + milliseconds(2)) << "at once";
  EXPECT_EQ(polls[1].len, 0u);
}

}  // namespace
}  // namespace dnbridge::test
