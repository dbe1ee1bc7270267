// Commands through DDS: applied by the simulated CDN127 and echoed back in
// PumpState; exclusive ownership between commanders of different strengths;
// the idle action once no commander is left; a bad command refused and
// reported.
#include <memory>

#include "bridge/profiles/cdn127/io_data.hpp"
#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

// A supervisor process that commands pumps.
class Commander : public TestCommander<dnbridge_PumpCommand> {
 public:
  using TestCommander::TestCommander;
  bool write(unsigned mac, bool pump_on, bool n2_ballast_on, std::uint16_t analog,
             Duration ahead = Duration::zero()) {
    return TestCommander::write(
        mac,
        [&](dnbridge_PumpCommand& c) {
          c.pump_on = pump_on;
          c.n2_ballast_on = n2_ballast_on;
          c.analog_output_raw = analog;
        },
        ahead);
  }
};

using profiles::cdn127::PumpOutputs;

class CommandTest : public BridgeTest {
 protected:
  // The echo: the outputs the device applied with its last answered poll.
  bool echoes(unsigned mac, bool pump_on, bool n2, std::uint16_t analog,
              std::string_view by) const {
    const auto* s = pumps_.latest(pump_mac(mac));
    return s && s->online && !s->outputs_idle && s->pump_on == pump_on && s->n2_ballast_on == n2 &&
           s->analog_output_raw == analog && dds::view(s->commanded_by) == by;
  }
  PumpOutputs device_outputs(unsigned mac) {
    return on_port([mac](sim::SimBackend& b) { return slave(b, mac).device().outputs(); });
  }
  sim::OutputCause device_cause(unsigned mac) {
    return on_port(
        [mac](sim::SimBackend& b) { return slave(b, mac).device().pump().last_cause(); });
  }
};

TEST_F(CommandTest, CommandChangesTheDeviceOutputsAndIsEchoedInPumpState) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  Commander supervisor("supervisor-1", 10);
  ASSERT_TRUE(supervisor.matched());
  EXPECT_EQ(device_outputs(1), PumpOutputs{});

  const auto sent = SteadyClock::now();
  ASSERT_TRUE(supervisor.write(1, true, true, 2048));
  ASSERT_TRUE(pumps_.until([&] { return echoes(1, true, true, 2048, "supervisor-1"); }));
  report("command written -> echo in PumpState", ms_since(sent));
  EXPECT_EQ(device_outputs(1), (PumpOutputs{true, true, 2048}));
  EXPECT_EQ(device_cause(1), sim::OutputCause::kPoll);
  // The other pumps are left alone.
  EXPECT_EQ(device_outputs(2), PumpOutputs{});
  EXPECT_TRUE(pumps_.latest(pump_mac(2))->outputs_idle);

  // A second command from the same commander replaces the first.
  ASSERT_TRUE(supervisor.write(1, false, true, 100));
  ASSERT_TRUE(pumps_.until([&] { return echoes(1, false, true, 100, "supervisor-1"); }));
  EXPECT_EQ(device_outputs(1), (PumpOutputs{false, true, 100}));
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(1));
    return n && n->counters.commands_accepted == 2;
  }));
}

// Commands written back to back, for four pumps: most come within the
// DDS input's hold-off of the take before them, and wait in the reader for
// its end (each pump's newest). None is stranded there: every pump ends with
// the last command written for it.
TEST_F(CommandTest, AFloodEndsWithEveryPumpsNewestCommand) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  Commander flood("flood", 10);
  ASSERT_TRUE(flood.matched());
  constexpr unsigned kPumps = 4;
  for (unsigned i = 0; i < 2000; ++i) {
    ASSERT_TRUE(flood.write(1 + i % kPumps, true, false, static_cast<std::uint16_t>(i)));
  }
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    ASSERT_TRUE(flood.write(mac, true, true, static_cast<std::uint16_t>(4000 + mac)));
  }
  ASSERT_TRUE(pumps_.until([&] {
    for (unsigned mac = 1; mac <= kPumps; ++mac) {
      if (!echoes(mac, true, true, static_cast<std::uint16_t>(4000 + mac), "flood")) return false;
    }
    return true;
  }));
  for (unsigned mac = 1; mac <= kPumps; ++mac) {
    EXPECT_EQ(device_outputs(mac),
              (PumpOutputs{true, true, static_cast<std::uint16_t>(4000 + mac)}));
  }
  // The hold-off did engage: back-to-back writes come microseconds apart,
  // well within 1 ms of the take before them.
  EXPECT_GT(bridge_->process_counters().command_holdoffs, 0u);
}

TEST_F(CommandTest, BadCommandIsRefusedAndReported) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  Commander supervisor("supervisor-1", 10);
  ASSERT_TRUE(supervisor.matched());
  ASSERT_TRUE(supervisor.write(3, true, false, 1000));
  ASSERT_TRUE(pumps_.until([&] { return echoes(3, true, false, 1000, "supervisor-1"); }));

  // 12-bit analog output: 5000 is refused, not clipped; nothing of it applied.
  ASSERT_TRUE(supervisor.write(3, false, true, 5000));
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(3));
    return n && n->counters.commands_refused == 1;
  }));
  const auto* n = nodes_.latest(pump_mac(3));
  EXPECT_NE(dds::view(n->last_command_refused).find("5000"), std::string_view::npos)
      << dds::view(n->last_command_refused);
  EXPECT_EQ(n->counters.commands_accepted, 1u);
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "command refused"));
  EXPECT_EQ(device_outputs(3), (PumpOutputs{true, false, 1000}));
  EXPECT_TRUE(echoes(3, true, false, 1000, "supervisor-1"));

  // A command for a pump this rack does not have is refused and logged.
  ASSERT_TRUE(supervisor.write(40, true, false, 0));
  ASSERT_TRUE(supervisor.acked());
  ASSERT_TRUE(pumps_.until([&] { return log_.contains(LogLevel::kWarn, "MAC 40 refused"); }));

  // The pump still takes good commands.
  ASSERT_TRUE(supervisor.write(3, false, true, 4095));
  ASSERT_TRUE(pumps_.until([&] { return echoes(3, false, true, 4095, "supervisor-1"); }));
  EXPECT_EQ(device_outputs(3), (PumpOutputs{false, true, 4095}));
}

TEST_F(CommandTest, StrongerCommanderWinsWeakerTakesOverThenIdleWhenAllAreGone) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  constexpr unsigned kMac = 2;
  auto weak = std::make_unique<Commander>("weak", 10);
  auto strong = std::make_unique<Commander>("strong", 20);
  ASSERT_TRUE(weak->matched());
  ASSERT_TRUE(strong->matched());

  ASSERT_TRUE(weak->write(kMac, true, false, 1000));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, false, 1000, "weak"); }));
  ASSERT_TRUE(strong->write(kMac, true, true, 3000));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, true, 3000, "strong"); }));

  // The weaker writes while the stronger lives: not delivered to the bridge.
  ASSERT_TRUE(weak->write(kMac, false, false, 1001));
  ASSERT_TRUE(weak->acked());
  ASSERT_TRUE(strong->write(kMac, true, true, 3001));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, true, 3001, "strong"); }));
  EXPECT_EQ(device_outputs(kMac), (PumpOutputs{true, true, 3001}));
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kMac));
    return n && n->counters.commands_accepted >= 3;
  }));
  EXPECT_EQ(nodes_.latest(pump_mac(kMac))->counters.commands_accepted, 3u);  // 1000, 3000, 3001

  // The stronger exits. The weaker, which repeats its command as a
  // supervisor does, takes over; the pump never idles in between.
  const std::size_t before_exit = pumps_.history().size();
  strong.reset();
  const auto exited = SteadyClock::now();
  ASSERT_TRUE(pumps_.until(
      [&] {
        if (echoes(kMac, false, true, 1002, "weak")) return true;
        EXPECT_TRUE(weak->write(kMac, false, true, 1002));
        return false;
      },
      kEventTimeout, milliseconds(50)));
  report("stronger commander gone -> weaker's command echoed", ms_since(exited));
  EXPECT_EQ(device_outputs(kMac), (PumpOutputs{false, true, 1002}));
  for (std::size_t i = before_exit; i < pumps_.history().size(); ++i) {
    const auto& r = pumps_.history()[i];
    if (r.sample.valid_data() && r.sample->mac == kMac) {
      EXPECT_FALSE(r.sample->outputs_idle) << "the pump idled between the two commanders";
    }
  }
  for (const auto& r : pumps_.history()) {
    if (r.sample.valid_data() && r.sample->mac == kMac) {
      EXPECT_NE(r.sample->analog_output_raw, 1001) << "a weaker writer's command was applied";
    }
  }

  // Every commander gone: the bridge polls idle and the CDN127 applies the
  // idle actions the bridge downloaded at start-up (the default: outputs
  // off, analog output 0 V, over this simulator's factory "hold").
  weak.reset();
  const auto gone = SteadyClock::now();
  ASSERT_TRUE(pumps_.until([&] {
    const auto* s = pumps_.latest(pump_mac(kMac));
    return s && s->outputs_idle && dds::view(s->commanded_by).empty();
  }));
  report("last commander gone -> idle in PumpState", ms_since(gone));
  EXPECT_EQ(device_cause(kMac), sim::OutputCause::kIdle);
  const PumpOutputs idle = device_outputs(kMac);
  EXPECT_FALSE(idle.pump_on);
  EXPECT_FALSE(idle.n2_ballast_on);
  EXPECT_EQ(idle.analog_out_raw, 0);
  EXPECT_TRUE(log_.contains(LogLevel::kInfo, "no live commander left"));
  // Polls continue (idle): the pump stays online.
  EXPECT_TRUE(pumps_.latest(pump_mac(kMac))->online);
}

TEST_F(CommandTest, CommanderThatWritesAndExitsAtOnceLeavesThePumpIdle) {
  // A one-shot client: its command and its departure may reach the bridge
  // together, as one sample of an instance that already has no writer left.
  // Whichever way they arrive, nobody commands the pump afterwards: idle.
  ASSERT_NO_FATAL_FAILURE(start_online());
  for (unsigned mac = 4; mac <= 7; ++mac) {
    auto one_shot = std::make_unique<Commander>("one-shot", 10);
    ASSERT_TRUE(one_shot->matched());
    ASSERT_TRUE(one_shot->write(mac, true, true, 777));
    one_shot.reset();
  }
  auto idle = [&] {
    for (unsigned mac = 4; mac <= 7; ++mac) {
      const auto* s = pumps_.latest(pump_mac(mac));
      if (!s || !s->outputs_idle || !dds::view(s->commanded_by).empty()) return false;
    }
    return true;
  };
  // Changes are published at once, and every state at least once per
  // publish period (1 s): a little more than one period sees the end state.
  const auto settled = SteadyClock::now() + milliseconds(1300);
  pumps_.until([&] { return SteadyClock::now() >= settled; }, seconds(2));
  EXPECT_TRUE(idle()) << "a pump stays commanded by a commander that is gone";
  for (unsigned mac = 4; mac <= 7; ++mac) {
    EXPECT_FALSE(device_outputs(mac).pump_on) << mac;
  }
}

// A commander whose clock runs an hour ahead commands a pump and leaves: its
// timestamps do not outrank the bridge's order of arrival, so a weaker
// commander's next command is applied at once, and with no commander left
// the pump goes idle within the command lease.
TEST_F(CommandTest, ACommanderStampingAnHourAheadDoesNotOutliveItsDeparture) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  constexpr unsigned kMac = 7;
  auto weak = std::make_unique<Commander>("weak", 1);
  ASSERT_TRUE(weak->matched());
  ASSERT_TRUE(weak->write(kMac, false, false, 0));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, false, false, 0, "weak"); }));

  {
    Commander ahead("an hour ahead", 50);
    ASSERT_TRUE(ahead.matched());
    ASSERT_TRUE(ahead.write(kMac, true, false, 0, seconds(3600)));
    ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, false, 0, "an hour ahead"); }));
    ASSERT_TRUE(ahead.acked());
  }  // deleted: it unregisters, stamped with its own (now older) time
  // The wrong clock is reported, with the commander's name.
  EXPECT_TRUE(log_.contains(LogLevel::kWarn,
                            "command from \"an hour ahead\" for port \"A\" MAC 7 is stamped 3"))
      << "no warning about the commander's clock";
  // The weaker commander's next command takes the pump.
  const auto left = SteadyClock::now();
  ASSERT_TRUE(weak->write(kMac, false, true, 0));
  ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, false, true, 0, "weak"); }))
      << "the weaker commander's command was dropped";
  report("commander an hour ahead gone -> weaker commander in control", ms_since(left));

  // Again with no other commander: idle within the lease.
  {
    Commander ahead("an hour ahead", 50);
    ASSERT_TRUE(ahead.matched());
    ASSERT_TRUE(ahead.write(kMac, true, false, 0, seconds(3600)));
    ASSERT_TRUE(pumps_.until([&] { return echoes(kMac, true, false, 0, "an hour ahead"); }));
    ASSERT_TRUE(ahead.acked());
    weak.reset();
  }
  ASSERT_TRUE(pumps_.until([&] {
    const auto* s = pumps_.latest(pump_mac(kMac));
    return s && s->outputs_idle && dds::view(s->commanded_by).empty();
  })) << "the pump stayed commanded by a departed writer";
  EXPECT_FALSE(device_outputs(kMac).pump_on);
}

}  // namespace
}  // namespace dnbridge::e2e
