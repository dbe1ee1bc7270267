// How long a commander that is present but silent stays in charge: the rack's
// bound on the command writer's lease (max_commander_lease_ms) and the
// optional command refresh (command_refresh_ms). Each commander is a process
// of its own (dnbridge_careless_client commander), beside the bridge in
// this one; the times each loss takes are reported.
#include <csignal>

#include "bridge_fixture.hpp"
#include "child_process.hpp"

namespace dnbridge::e2e {
namespace {

constexpr unsigned kMac = 3;
constexpr auto kLease = milliseconds(2000);
constexpr auto kRefresh = milliseconds(500);
// The pumps' poll period in the embedded default rack.
constexpr auto kPoll = milliseconds(100);
// What a loaded machine adds to a bound: the state sample's way to the test
// and the scheduling of three processes.
constexpr auto kMargin = milliseconds(700);

class CommanderBoundTest : public BridgeTest {
 protected:
  // Pump kMac with a command refresh.
  static daemon::DaemonConfig refresh_config() {
    auto c = rack_config();
    for (auto& n : c.ports.at(0).nodes) {
      if (n.pump.node.mac.value() == kMac) n.pump.command_refresh = kRefresh;
    }
    return c;
  }

  ChildProcess& commander(const std::string& issuer, int strength, Duration lease,
                          Duration deadline) {
    ChildOptions options;
    options.control = true;
    const auto ms = [](Duration d) {
      return std::to_string(std::chrono::duration_cast<milliseconds>(d).count());
    };
    commanders_.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{DNBRIDGE_CARELESS_CLIENT, std::to_string(test_domain()),
                                 "commander", std::to_string(kMac), std::to_string(strength),
                                 ms(lease), ms(deadline), issuer},
        options));
    return *commanders_.back();
  }

  bool echoes(std::string_view by) const {
    const auto* s = pumps_.latest(pump_mac(kMac));
    return s && s->online && !s->outputs_idle && s->pump_on && dds::view(s->commanded_by) == by;
  }
  bool idle(std::string_view reason = {}) const {
    const auto* s = pumps_.latest(pump_mac(kMac));
    return s && s->online && s->outputs_idle && dds::view(s->commanded_by).empty() &&
           (reason.empty() || dds::view(s->idle_reason) == reason);
  }
  bool device_pump_on() {
    return on_port([](sim::SimBackend& b) { return slave(b, kMac).device().outputs().pump_on; });
  }
  const dnbridge_PortStatus* port_status() const {
    return ports_.latest([](const dnbridge_PortStatus& p) { return dds::view(p.port) == kPort; });
  }

  std::vector<std::unique_ptr<ChildProcess>> commanders_;
};

TEST_F(CommanderBoundTest, ACommanderOfferingAnInfiniteLeaseIsRefusedAndThePumpStaysIdle) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto& c = commander("infinite lease", 10, Duration::zero(), Duration::zero());
  // The writer sees the bridge's reader refuse it: liveliness.
  ASSERT_EQ(c.read_line(milliseconds(15000)),
            "refused " + std::to_string(DDS_LIVELINESS_QOS_POLICY_ID));
  ASSERT_TRUE(c.send_line("write"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "written");
  // The bridge says who it refused, and PortStatus counts it.
  ASSERT_TRUE(ports_.until(
      [&] {
        const auto* p = port_status();
        return p && p->commanders_refused == 1;
      },
      seconds(10)))
      << "PortStatus does not count the refused commander";
  EXPECT_EQ(port_status()->max_commander_lease_ms, 10000u);
  EXPECT_TRUE(log_.contains(LogLevel::kWarn,
                            "refused as a commander: offers a liveliness lease "
                            "of infinite"));
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "\"infinite lease\""))
      << "the refusal does not name the commander's participant";
  // Nothing it writes commands the pump: two publish periods show it idle.
  EXPECT_FALSE(pumps_.until([&] { return !idle(); }, milliseconds(2000)));
  EXPECT_FALSE(device_pump_on());
}

TEST_F(CommanderBoundTest, ACommanderAtTheBoundCommands) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto& c = commander("at the bound", 10, dds::kDefaultMaxCommanderLease, Duration::zero());
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(c.send_line("write"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes("at the bound"); }));
  EXPECT_TRUE(device_pump_on());
  ASSERT_TRUE(ports_.until([&] { return port_status() != nullptr; }));
  EXPECT_EQ(port_status()->commanders_refused, 0u);
  EXPECT_EQ(port_status()->endpoints_unmatched, 0u);
}

TEST_F(CommanderBoundTest, AStoppedCommanderProcessLosesItsPumpWithinItsLeaseAndOnePoll) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto& c = commander("to be stopped", 10, kLease, Duration::zero());
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(c.send_line("write"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes("to be stopped"); }));
  // The whole process frozen: its DDS threads too.
  const auto stopped = SteadyClock::now();
  ASSERT_TRUE(c.signal(SIGSTOP));
  const bool idled = pumps_.until([&] { return idle("idle: no live commander"); },
                                  kLease + kPoll + kMargin, milliseconds(20));
  const double took = ms_since(stopped);
  (void)c.signal(SIGCONT);
  ASSERT_TRUE(idled) << "the pump stayed commanded by a frozen commander";
  EXPECT_GE(took, 0.9 * static_cast<double>(kLease.count()))
      << "idle before the lease ran out: not the lease that idled it";
  report("commander process stopped (SIGSTOP, 2 s lease) -> pump idle", took);
  EXPECT_FALSE(device_pump_on());
}

TEST_F(CommanderBoundTest, AKilledCommanderProcessLosesItsPumpWithinItsLeaseAndOnePoll) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto& c = commander("to be killed", 10, kLease, Duration::zero());
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(c.send_line("write"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes("to be killed"); }));
  // No unregistration, no goodbye: only the lease tells.
  const auto killed = SteadyClock::now();
  ASSERT_TRUE(c.signal(SIGKILL));
  const bool idled = pumps_.until([&] { return idle("idle: no live commander"); },
                                  kLease + kPoll + kMargin, milliseconds(20));
  const double took = ms_since(killed);
  ASSERT_TRUE(idled) << "the pump stayed commanded by a killed commander";
  report("commander process killed (SIGKILL, 2 s lease) -> pump idle", took);
  EXPECT_FALSE(device_pump_on());
}

TEST_F(CommanderBoundTest, ACommanderThatUnregistersItsInstanceLosesThePumpAtOnce) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  auto& c = commander("unregistering", 10, kLease, Duration::zero());
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(c.send_line("write"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(pumps_.until([&] { return echoes("unregistering"); }));
  const auto unregistered = SteadyClock::now();
  ASSERT_TRUE(c.send_line("unregister"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "unregistered");
  ASSERT_TRUE(pumps_.until([&] { return idle("idle: no live commander"); }, kPoll + kMargin,
                           milliseconds(20)))
      << "the pump stayed commanded after its commander unregistered the instance";
  report("commander unregistered its instance (writer live) -> pump idle", ms_since(unregistered));
  EXPECT_FALSE(device_pump_on());
}

TEST_F(CommanderBoundTest, ASilentCommanderLosesItsPumpWithinTheRefreshAndOnePoll) {
  ASSERT_NO_FATAL_FAILURE(start_online(refresh_config()));
  // A commander offering no deadline cannot command a node with a refresh.
  auto& careless = commander("no deadline", 20, kLease, Duration::zero());
  // Matched by the other nodes' readers, refused by those of the node with a
  // refresh: whichever it sees first.
  const auto first = careless.read_line(milliseconds(15000));
  ASSERT_TRUE(first == "matched" ||
              first == "refused " + std::to_string(DDS_DEADLINE_QOS_POLICY_ID))
      << first.value_or("nothing");
  auto& c = commander("refreshing", 10, kLease, kRefresh);
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(careless.send_line("write"));
  ASSERT_EQ(careless.read_line(milliseconds(5000)), "written");
  ASSERT_TRUE(c.send_line("refresh 125"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("refreshing"); }))
      << "a stronger commander offering no deadline took a node with a command refresh";
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kMac));
    return n && n->command_refresh_ms == 500;
  }));
  // It commands the other nodes: said, not counted as refused.
  ASSERT_TRUE(ports_.until(
      [&] {
        return log_.contains(LogLevel::kInfo,
                             "offers no deadline; it does not command the nodes with "
                             "command_refresh_ms = 500 (port A: 3)");
      },
      seconds(10)))
      << "the bridge does not say which nodes a commander without a deadline cannot command";
  EXPECT_EQ(port_status()->commanders_refused, 0u);

  // Its DDS stack alive, its liveliness asserted: only its writes stop.
  ASSERT_TRUE(c.send_line("silent"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "silent");
  const auto silent = SteadyClock::now();
  const bool idled = pumps_.until([&] { return idle("idle: commander silent for 500 ms"); },
                                  kRefresh + kPoll + kMargin, milliseconds(20));
  const double took = ms_since(silent);
  ASSERT_TRUE(idled) << "a commander that stopped writing still holds the pump";
  report("commander silent (500 ms command refresh) -> pump idle", took);
  EXPECT_FALSE(device_pump_on());
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "commander refreshing silent for 500 ms"));
  // Writing again, it commands again.
  ASSERT_TRUE(c.send_line("refresh 125"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("refreshing"); }));
}

// A silent stronger commander loses the pump at its refresh, and a weaker
// one that keeps writing takes it over with its next write: the bridge takes
// the node's commands from then on by a reader of its own, made afresh, in
// which the silent writer owns nothing (in the readers it had written to,
// it stays the owner while it is live). The stronger one writing again
// takes the pump back; once it is gone, the weaker one's next write commands.
TEST_F(CommanderBoundTest, AWeakerLiveCommanderTakesOverFromASilentStrongerOne) {
  ASSERT_NO_FATAL_FAILURE(start_online(refresh_config()));
  auto& strong = commander("strong", 50, kLease, kRefresh);
  auto& weak = commander("weak", 1, kLease, kRefresh);
  ASSERT_EQ(strong.read_line(milliseconds(15000)), "matched");
  ASSERT_EQ(weak.read_line(milliseconds(15000)), "matched");
  constexpr auto kWeakWrites = milliseconds(125);
  ASSERT_TRUE(weak.send_line("refresh 125"));
  ASSERT_EQ(weak.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("weak"); }));
  ASSERT_TRUE(strong.send_line("refresh 125"));
  ASSERT_EQ(strong.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("strong"); }));

  for (int round = 1; round <= 2; ++round) {
    SCOPED_TRACE("silence " + std::to_string(round));
    ASSERT_TRUE(strong.send_line("silent"));
    ASSERT_EQ(strong.read_line(milliseconds(5000)), "silent");
    const auto silent = SteadyClock::now();
    const std::size_t before = pumps_.history().size();
    const bool weak_took = pumps_.until([&] { return echoes("weak"); },
                                        kRefresh + kWeakWrites + kPoll + kMargin, milliseconds(20));
    const double took = ms_since(silent);
    ASSERT_TRUE(weak_took) << "a weaker live commander did not take over from a silent one";
    // Through idle: the silent commander's command lapsed first.
    const auto lapsed = [](const dnbridge_PumpState& s) {
      return s.mac == kMac && s.outputs_idle &&
             dds::view(s.idle_reason) == "idle: commander silent for 500 ms";
    };
    const bool idled = !pumps_.since(before, lapsed).empty();
    EXPECT_TRUE(idled) << "the pump went from the silent commander to the weaker one without idle";
    report(
        "stronger commander silent (500 ms refresh), weaker one writing every 125 ms -> "
        "weaker one in control",
        took);
    // The stronger one writing again takes the pump back.
    ASSERT_TRUE(strong.send_line("refresh 125"));
    ASSERT_EQ(strong.read_line(milliseconds(5000)), "refreshing");
    ASSERT_TRUE(pumps_.until([&] { return echoes("strong"); }, seconds(5), milliseconds(20)))
        << "a stronger commander writing again did not take its pump back";
  }

  // The stronger one leaves (its writer deleted): the weaker one's next
  // write commands.
  ASSERT_TRUE(strong.close_input());
  ASSERT_EQ(strong.wait_for(milliseconds(5000)), 0);
  const auto left = SteadyClock::now();
  ASSERT_TRUE(pumps_.until([&] { return echoes("weak"); }, seconds(5), milliseconds(20)))
      << "the weaker live commander did not take over once the stronger one left";
  report("stronger commander gone -> weaker one in control", ms_since(left));
  EXPECT_TRUE(device_pump_on());
}

// A reload that changes the refresh of a node whose commands its own reader
// takes (its commander went silent once) leaves the command in force: the
// node's class of the new refresh takes its commands at once, and the
// command does not lapse while its commander keeps writing.
TEST_F(CommanderBoundTest, AReloadThatChangesTheRefreshOfANodeWithItsOwnReaderKeepsItsCommand) {
  static constexpr auto kLonger = milliseconds(800);
  daemon::ReloadSource reload;
  reload.load = [] {
    auto c = refresh_config();
    for (auto& n : c.ports.at(0).nodes) {
      if (n.pump.node.mac.value() == kMac) n.pump.command_refresh = kLonger;
    }
    return c;
  };
  ASSERT_NO_FATAL_FAILURE(start_online(refresh_config(), std::move(reload)));
  auto& c = commander("refreshing", 10, kLease, kRefresh);
  ASSERT_EQ(c.read_line(milliseconds(15000)), "matched");
  ASSERT_TRUE(c.send_line("refresh 125"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("refreshing"); }));
  // Silent once: from then on the node's own reader takes its commands.
  ASSERT_TRUE(c.send_line("silent"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "silent");
  ASSERT_TRUE(pumps_.until([&] { return idle("idle: commander silent for 500 ms"); }));
  ASSERT_TRUE(c.send_line("refresh 125"));
  ASSERT_EQ(c.read_line(milliseconds(5000)), "refreshing");
  ASSERT_TRUE(pumps_.until([&] { return echoes("refreshing"); }));

  const auto r = bridge_->reload();
  ASSERT_EQ(r.status, daemon::ReloadStatus::kApplied) << r.message;
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kMac));
    return n && n->command_refresh_ms == 800;
  }));
  const std::size_t after = pumps_.history().size();
  // Three of the new refreshes: a command no reader took would have lapsed.
  (void)pumps_.until([] { return false; }, 3 * kLonger, milliseconds(50));
  for (const dnbridge_PumpState* s :
       pumps_.since(after, [](const dnbridge_PumpState& s) { return s.mac == kMac; })) {
    EXPECT_FALSE(s->outputs_idle) << "the command lapsed after the reload: "
                                  << dds::view(s->idle_reason);
  }
  EXPECT_TRUE(echoes("refreshing"));
  EXPECT_FALSE(log_.contains(LogLevel::kWarn, "commander refreshing silent for 800 ms"));
}

}  // namespace
}  // namespace dnbridge::e2e
