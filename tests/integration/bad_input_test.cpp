// Bad input never crashes or stalls the scan: frames of unexpected length or
// identifier, malformed or unexpected explicit answers, fragments out of
// order are counted, logged at a limited rate, and polling goes on.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "bridge/devicenet/wire/identifier.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

using devicenet::group2_id;
using devicenet::Group2Message;

// A misbehaving node: every few milliseconds, a frame that no correct
// DeviceNet node would send.
class RogueNode final : public sim::SimEndpoint {
 public:
  RogueNode(sim::SimWorld& world, std::vector<unsigned> victims, TimePoint start)
      : world_(world),
        handle_(world.bus().attach(*this)),
        victims_(std::move(victims)),
        next_(start) {
    world.add(*this);
  }
  ~RogueNode() override { world_.remove(*this); }

  void on_frame(const can::CanFrame&, TimePoint) override {}
  TimePoint next_deadline() const override { return next_; }
  void on_timer(TimePoint now) override {
    next_ = now + milliseconds(7);
    const unsigned victim = victims_[sent_ % victims_.size()];
    const auto m = mac(victim);
    can::CanFrame f;
    std::uniform_int_distribution<int> byte(0, 255);
    auto fill = [&](std::uint8_t len) {
      f.len = len;
      for (std::uint8_t i = 0; i < len; ++i) f.data[i] = static_cast<std::uint8_t>(byte(rng_));
    };
    switch (sent_ % 8) {
      case 0:  // an identifier outside the DeviceNet groups
        f.id = 0x7F0 + static_cast<std::uint32_t>(sent_ % 16);
        fill(8);
        break;
      case 1:  // a poll response of the wrong size (the CDN127 preset produces 6)
        f.id = 0x3C0 + victim;
        fill(static_cast<std::uint8_t>(1 + sent_ % 5));
        break;
      case 2:  // an explicit answer to the master with random bytes
        f.id = group2_id(m, Group2Message::kSlaveExplicitResponse);
        fill(static_cast<std::uint8_t>(sent_ % 9));
        f.data[0] = static_cast<std::uint8_t>(f.data[0] & 0xC0);  // header MAC 0: the master's
        if (f.len == 0) f.len = 1;
        break;
      case 3:  // a response fragment out of order (middle, count 17)
        f.id = group2_id(m, Group2Message::kSlaveExplicitResponse);
        f.len = 5;
        f.data = {0x80, 0x51, 0x01, 0x02, 0x03};
        break;
      case 4:  // an error response cut short
        f.id = group2_id(m, Group2Message::kSlaveExplicitResponse);
        f.len = 2;
        f.data = {0x00, 0x94};
        break;
      case 5:  // a duplicate MAC message of the wrong size
        f.id = group2_id(m, Group2Message::kDuplicateMacCheck);
        fill(3);
        break;
      case 6:  // Group 3 and Group 4 traffic nobody here uses
        f.id = 0x600 + static_cast<std::uint32_t>(sent_ % 0x1C0);
        fill(4);
        break;
      default:  // an empty explicit frame
        f.id = group2_id(m, Group2Message::kSlaveExplicitResponse);
        f.len = 0;
        break;
    }
    ++sent_;
    world_.bus().sink(handle_).send(f, now);
  }
  std::uint64_t sent() const { return sent_; }

 private:
  sim::SimWorld& world_;
  sim::NodeHandle handle_;
  std::vector<unsigned> victims_;
  TimePoint next_;
  std::mt19937 rng_{7};
  std::uint64_t sent_ = 0;
};

TEST(BadInput, GarbageOnTheBusIsCountedAndTheScanGoesOn) {
  CountingLogSink log;
  sim::SimRack rack(rack_config({1, 2, 3, 4}), &log);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));

  RogueNode rogue(rack.world(), {1, 2, 3, 4}, rack.now());
  rack.world().run_for(seconds(30));
  ASSERT_GT(rogue.sent(), 4000u);

  std::uint64_t poll_errors = 0, explicit_bad = 0;
  for (unsigned m : {1u, 2u, 3u, 4u}) {
    const auto& node = *rack.scanner().node(mac(m));
    EXPECT_EQ(node.state(), NodeState::kOnline) << m << ": " << node.reason();
    EXPECT_EQ(node.counters().reconnects, 0u) << m;
    poll_errors += node.counters().errors;
    explicit_bad +=
        node.explicit_counters().malformed_frames + node.explicit_counters().unexpected_frames;
  }
  const auto& port = rack.scanner().counters();
  EXPECT_GT(port.invalid_identifiers, 400u);
  EXPECT_GT(port.foreign_frames, 400u);
  EXPECT_GT(poll_errors, 400u);
  EXPECT_GT(explicit_bad, 1500u);
  // Logged, but not one line per bad frame.
  EXPECT_GT(log.warnings, 0u);
  EXPECT_LT(log.warnings, 200u) << log.last_warning;

  // And the pumps still do what they are told.
  profiles::cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 777;
  for (unsigned m : {1u, 2u, 3u, 4u})
    ASSERT_TRUE(rack.pumps().command(mac(m), out, rack.now()).ok());
  rack.world().run_for(milliseconds(300));
  for (unsigned m : {1u, 2u, 3u, 4u}) {
    EXPECT_EQ(rack.device(mac(m)).device().outputs(), out) << m;
    EXPECT_EQ(rack.pumps().pump(mac(m))->outputs_applied, out) << m;
  }
}

TEST(BadInput, CorruptedPollResponsesAreCountedNotTaken) {
  sim::SimRack rack(rack_config({6}));
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
  // One poll response in ten loses a byte on its way.
  auto rule = sim::FaultRule::corrupt(0x3C0 + 6, sim::Corruption::kTruncate, 1);
  rule.rate = 0.1;
  rack.world().bus().faults().add(rule);
  rack.device(mac(6)).device().pump().set_analog_input(0, 1234);
  rack.world().run_for(seconds(20));
  const auto& node = *rack.scanner().node(mac(6));
  EXPECT_EQ(node.state(), NodeState::kOnline);
  // 20 s at 10 polls/s, one in ten corrupted: about 20.
  EXPECT_GT(node.counters().errors, 8u);
  EXPECT_LT(node.counters().errors, 40u);
  EXPECT_EQ(node.last_error().kind, devicenet::NodeError::Kind::kPollLength);
  EXPECT_EQ(node.last_error().got, 5u);
  EXPECT_EQ(node.last_error().expected, 6u);
  // What was taken is what the device sent.
  EXPECT_EQ(rack.pumps().pump(mac(6))->inputs.analog_inputs_raw[0], 1234);
}

// Node 6 online on a device that keeps its outputs on a Release (only an
// idle poll turns its pump off), commanded on with the analog output at 777.
void start_running_pump_that_keeps_outputs_on_release(std::unique_ptr<sim::SimRack>& out) {
  auto config = rack_config({6});
  config.create_devices = false;
  out = std::make_unique<sim::SimRack>(std::move(config));
  sim::SimRack& rack = *out;
  sim::SlaveOptions options = sim::default_slave_options(mac(6));
  options.release_keeps_outputs = true;
  rack.add_device(std::move(options), std::nullopt);
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
  profiles::cdn127::PumpOutputs on;
  on.pump_on = true;
  on.analog_out_raw = 777;
  ASSERT_TRUE(rack.pumps().command(mac(6), on, rack.now()).ok());
  rack.world().run_for(milliseconds(300));
  ASSERT_EQ(rack.device(mac(6)).device().outputs(), on);
}

// Ten bad poll responses in a row while the pump runs: the node is lost, and
// its outputs go idle with one poll before the connections are released. The
// device is not left with the outputs last commanded until its own watchdog,
// nor released with them (what a device does on a Release, the manual does
// not say).
TEST(BadInput, BadPollResponsesLoseTheNodeWithItsOutputsIdledFirst) {
  std::unique_ptr<sim::SimRack> running;
  ASSERT_NO_FATAL_FAILURE(start_running_pump_that_keeps_outputs_on_release(running));
  sim::SimRack& rack = *running;

  // The master's frames to node 6 from here on.
  std::vector<can::CanFrame> to_node;
  rack.world().bus().set_tap([&](const sim::WireFrame& w) {
    const auto id = devicenet::decode_identifier(w.frame.id);
    if (id && id->group == devicenet::MessageGroup::k2 && id->mac == mac(6)) {
      to_node.push_back(w.frame);
    }
  });
  // The next ten poll responses each lose a byte.
  auto rule = sim::FaultRule::corrupt(0x3C0 + 6, sim::Corruption::kTruncate, 1);
  rule.count = 10;
  rack.world().bus().faults().add(rule);
  const auto& node = *rack.scanner().node(mac(6));
  ASSERT_TRUE(
      rack.world().run_until([&] { return node.state() != NodeState::kOnline; }, seconds(5)));
  rack.world().run_for(milliseconds(5));
  EXPECT_NE(node.reason().find("10 bad poll responses in a row"), std::string::npos)
      << node.reason();
  EXPECT_FALSE(rack.device(mac(6)).device().outputs().pump_on)
      << "the outputs are idle at once, not after the device's watchdog";

  // On the wire: the last poll before the first Release is the idle one.
  const auto message = [](const can::CanFrame& f) {
    return devicenet::decode_identifier(f.id)->message_id;
  };
  const auto release = std::find_if(to_node.begin(), to_node.end(), [&](const can::CanFrame& f) {
    return message(f) ==
               static_cast<std::uint8_t>(devicenet::Group2Message::kUnconnectedExplicitRequest) &&
           f.len >= 2 && f.data[1] == 0x4C;
  });
  ASSERT_NE(release, to_node.end());
  const auto last_poll = std::find_if(
      std::make_reverse_iterator(release), to_node.rend(), [&](const can::CanFrame& f) {
        return message(f) == static_cast<std::uint8_t>(devicenet::Group2Message::kMasterIoPoll);
      });
  ASSERT_NE(last_poll, to_node.rend());
  EXPECT_EQ(last_poll->len, 0u) << "an idle poll";
}

// The answer to a stopping node's idle poll comes bad: the node is released
// and stops all the same, not held until its port gives up waiting.
TEST(BadInput, ABadAnswerToTheIdlePollOfAShutdownStillEndsInARelease) {
  sim::SimRack rack(rack_config({6}));
  rack.start();
  ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
  // Every poll response from here on loses a byte.
  rack.world().bus().faults().add(
      sim::FaultRule::corrupt(0x3C0 + 6, sim::Corruption::kTruncate, 1));
  const auto& node = *rack.scanner().node(mac(6));
  const auto errors = node.counters().errors;
  rack.scanner().stop(rack.now());
  ASSERT_TRUE(rack.world().run_until([&] { return rack.scanner().stopped(); }, seconds(2)));
  EXPECT_EQ(node.state(), NodeState::kStopped) << node.reason();
  EXPECT_GT(node.counters().errors, errors) << "the answer was a bad one";
}

// Stopped while a poll is outstanding, and neither it nor the idle poll
// after it is answered: the idle poll still goes before the Release, so a
// device that keeps its outputs on a Release does not keep the pump on.
TEST(BadInput, AStopWhoseOutstandingPollGoesUnansweredStillPollsIdleFirst) {
  std::unique_ptr<sim::SimRack> running;
  ASSERT_NO_FATAL_FAILURE(start_running_pump_that_keeps_outputs_on_release(running));
  sim::SimRack& rack = *running;

  // From here on no poll is answered; stop right after a poll went out.
  rack.world().bus().faults().add(sim::FaultRule::drop(0x3C0 + 6));
  const std::uint32_t poll = devicenet::group2_id(mac(6), devicenet::Group2Message::kMasterIoPoll);
  std::vector<can::CanFrame> to_node;
  bool polled = false;
  rack.world().bus().set_tap([&](const sim::WireFrame& w) {
    polled = polled || w.frame.id == poll;
    if ((w.frame.id & 0x7F8) == (poll & 0x7F8) && polled) to_node.push_back(w.frame);
  });
  ASSERT_TRUE(rack.world().run_until([&] { return polled; }, seconds(1)));
  to_node.clear();
  rack.scanner().stop(rack.now());
  ASSERT_TRUE(rack.world().run_until([&] { return rack.scanner().stopped(); }, seconds(2)));
  EXPECT_FALSE(rack.device(mac(6)).device().outputs().pump_on) << "released with the pump on";
  // On the wire after the stop: the idle poll, then the Release.
  ASSERT_GE(to_node.size(), 2u);
  EXPECT_EQ(to_node[0].id, poll);
  EXPECT_EQ(to_node[0].len, 0u);
  EXPECT_EQ(to_node[1].id,
            devicenet::group2_id(mac(6), devicenet::Group2Message::kUnconnectedExplicitRequest));
  EXPECT_EQ(to_node[1].data[1], 0x4C);
}

// An analog input off the 0..4095 scale (a failed converter, 4096 and
// 0xFFFF): that channel is marked and counted; the discrete inputs and the
// other channel of the same responses keep coming, so an alarm that comes
// meanwhile is seen.
TEST(BadInput, AnAnalogInputOffTheScaleFailsThatChannelOnly) {
  for (const std::uint16_t raw : {std::uint16_t{4096}, std::uint16_t{0xFFFF}}) {
    SCOPED_TRACE(raw);
    sim::SimRack rack(rack_config({6}));
    rack.start();
    ASSERT_TRUE(rack.world().run_until([&] { return rack.all_online(); }, seconds(20)));
    sim::Cdn127Device& device = rack.device(mac(6)).device().device();
    const rack::PumpView& view = *rack.pumps().pump(mac(6));
    device.pump().set_analog_input(0, 1234);
    device.fail_analog_input(1, raw);
    rack.world().run_for(seconds(1));
    EXPECT_EQ(view.inputs.analog_inputs_raw[1], raw);
    EXPECT_FALSE(view.inputs.analog_input_in_range[1]);
    EXPECT_EQ(view.inputs.analog_inputs_raw[0], 1234);
    EXPECT_TRUE(view.inputs.analog_input_in_range[0]);
    EXPECT_GE(view.responses_with_invalid_inputs, 9u);  // ten polls a second
    ASSERT_TRUE(view.inputs.pump.has_value());
    EXPECT_FALSE(view.inputs.pump->alarm_active);

    // An alarm while the channel is still off the scale: seen at once.
    device.pump().set_alarm(true, rack.now());
    const TimePoint raised = rack.now();
    ASSERT_TRUE(rack.world().run_until(
        [&] { return view.inputs.pump && view.inputs.pump->alarm_active; }, seconds(1)));
    EXPECT_LE(rack.now() - raised, milliseconds(110));  // the next poll
    EXPECT_GT(view.inputs_time, raised);
    const auto& node = *rack.scanner().node(mac(6));
    EXPECT_EQ(node.state(), NodeState::kOnline);
    EXPECT_EQ(node.counters().errors, 0u) << "a full-size response is no poll error";

    // The converter back: the channel is valid again.
    device.fail_analog_input(1, std::nullopt);
    rack.world().run_for(milliseconds(200));
    EXPECT_TRUE(view.inputs.analog_input_in_range[1]);
    EXPECT_TRUE(view.inputs.all_in_range());
  }
}

}  // namespace
}  // namespace dnbridge::test
