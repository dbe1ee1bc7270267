// The outputs' safe state end to end: what the master downloads into a
// CDN127 whose E2 would keep a pump running, what the device then does when
// its master goes idle, silent or away, and how a node comes back after a
// device fault or a lost bus. The devices here leave the factory with
// sim::kUnsafeFactoryOutputActions (every output held on a fault and on
// idle): a pump that goes off does so because of what the master did.
// Master and simulated devices on the in-process bus, fake clock.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <vector>

#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;
using cdn127::AnalogAction;
using cdn127::DiscreteAction;
using cdn127::SafeStateSource;
using ::testing::HasSubstr;

constexpr unsigned kMac = 7;
// Faulted nodes are re-checked this often here (10 s by default); a start-up
// on this bus takes well under a second.
constexpr Duration kFaultRecheck = seconds(3);
constexpr Duration kStartUp = seconds(1);
// Long enough for two re-checks of a faulted node.
constexpr Duration kTwoRechecks = 2 * kFaultRecheck + kStartUp;

// What the master sent node kMac, from the wire.
struct Wire {
  struct Poll {
    TimePoint end;
    std::size_t len;
  };
  std::vector<Poll> polls;
  unsigned safe_state_sets = 0;  // Set_Attribute_Single to a DOP or the AOP

  std::size_t polls_after(TimePoint t) const {
    std::size_t n = 0;
    for (const auto& p : polls) n += p.end > t ? 1u : 0u;
    return n;
  }
};

class SafeStateRack : public ::testing::Test {
 protected:
  using ConfigAdjust = std::function<void(sim::SimRackConfig&)>;
  using DeviceAdjust = std::function<void(sim::SlaveOptions&)>;

  // One pump at kMac (poll period 100 ms, EPR 500 ms) on a device with the
  // unsafe factory actions; `before_start` has the powered-off device before
  // the master starts.
  void build(const ConfigAdjust& adjust_config = {}, const DeviceAdjust& adjust_device = {},
             const std::function<void(sim::Cdn127Device&)>& before_start = {}) {
    auto config = rack_config({kMac});
    config.create_devices = false;
    config.port.fault_recheck = kFaultRecheck;
    if (adjust_config) adjust_config(config);
    rack_ = std::make_unique<sim::SimRack>(std::move(config), &log_);
    rack_->observe(events_);
    sim::SlaveOptions options = sim::default_slave_options(mac(kMac));
    options.factory_output_actions = sim::kUnsafeFactoryOutputActions;
    if (adjust_device) adjust_device(options);
    rack_->world().bus().set_tap([this](const sim::WireFrame& f) { count(f); });
    rack_->add_device(std::move(options), std::nullopt);
    if (before_start) before_start(device());
    rack_->start();
  }

  void count(const sim::WireFrame& f) {
    if (f.sender != rack_->master().handle()) return;
    const auto& d = f.frame.data;
    if (f.frame.id == devicenet::group2_id(mac(kMac), devicenet::Group2Message::kMasterIoPoll)) {
      wire_.polls.push_back({f.end, f.frame.len});
    }
    // Unfragmented [hdr][service][class][instance][attribute][value...].
    if (f.frame.id ==
            devicenet::group2_id(mac(kMac), devicenet::Group2Message::kMasterExplicitRequest) &&
        f.frame.len >= 5 && (d[0] & 0x80) == 0 && d[1] == 0x10 &&
        (d[2] == cdn127::class_id::kDiscreteOutputPoint ||
         d[2] == cdn127::class_id::kAnalogOutputPoint)) {
      ++wire_.safe_state_sets;
    }
  }

  sim::SimWorld& world() { return rack_->world(); }
  TimePoint now() { return rack_->now(); }
  const rack::PumpView& view() { return *rack_->pumps().pump(mac(kMac)); }
  const devicenet::Node& node() { return *rack_->scanner().node(mac(kMac)); }
  sim::Cdn127Slave& slave() { return rack_->device(mac(kMac)).device(); }
  sim::Cdn127Device& device() { return slave().device(); }
  const cdn127::PumpOutputs& outputs() { return slave().outputs(); }

  bool run_until_state(NodeState state, Duration timeout) {
    return world().run_until([&] { return view().state == state; }, timeout);
  }
  Status command(const cdn127::PumpOutputs& out) {
    return rack_->pumps().command(mac(kMac), out, now());
  }
  // Every output on: pump, N2 ballast, analog output at 3000.
  static cdn127::PumpOutputs all_on() {
    cdn127::PumpOutputs out;
    out.pump_on = true;
    out.n2_ballast_on = true;
    out.analog_out_raw = 3000;
    return out;
  }
  // Commands every output on and waits until the device has them.
  void command_all_on() {
    ASSERT_TRUE(command(all_on()).ok()) << view().last_command_refused;
    ASSERT_TRUE(world().run_until([&] { return outputs() == all_on(); }, seconds(1)));
  }

  // The master falls silent: off the bus, sending nothing (its process
  // hangs, its cable is pulled, its controller is bus-off).
  void silence_master() { (void)world().bus().detach(rack_->master().handle()); }
  void unsilence_master() { (void)world().bus().reattach(rack_->master().handle()); }

  // Back online after a loss: idle, the device's pump off and kept off
  // until a new command, which then applies.
  void expect_idle_until_a_new_command() {
    EXPECT_EQ(view().state, NodeState::kOnline) << view().reason;
    EXPECT_EQ(view().idle_reason(), "idle: waiting for a new command after reconnection");
    EXPECT_FALSE(view().outputs_requested.has_value());
    const std::size_t polls = wire_.polls.size();
    world().run_for(seconds(3));
    EXPECT_GT(wire_.polls.size(), polls + 20) << "not polled while waiting";
    EXPECT_EQ(view().state, NodeState::kOnline) << view().reason;
    EXPECT_FALSE(outputs().pump_on) << "the pump started without a new command";
    EXPECT_FALSE(outputs().n2_ballast_on);
    EXPECT_EQ(outputs().analog_out_raw, 0);
    EXPECT_TRUE(view().outputs_idle);
    EXPECT_EQ(node().counters().polls - loss_.polls,
              node().counters().idle_polls - loss_.idle_polls)
        << "a poll with outputs went out";

    ASSERT_TRUE(command(all_on()).ok()) << view().last_command_refused;
    EXPECT_TRUE(world().run_until([&] { return outputs() == all_on(); }, milliseconds(200)));
    world().run_for(node().config().poll_period);  // its answer, in the view
    EXPECT_FALSE(view().outputs_idle);
    EXPECT_EQ(view().outputs_applied, all_on());
    EXPECT_EQ(view().idle_reason(), "");
  }

  CountingLogSink log_;
  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
  Wire wire_;
  // The node's poll counters when it was lost.
  struct {
    std::uint64_t polls = 0;
    std::uint64_t idle_polls = 0;
  } loss_;
  void note_loss() { loss_ = {node().counters().polls, node().counters().idle_polls}; }
};

// ---------------------------------------------------------------------------
// The download: the device's E2 gets the configured actions, and they are
// what turns the pump off.

class SafeStateDownload : public SafeStateRack {};

TEST_F(SafeStateDownload, TheConfiguredActionsTurnAnUnsafeDevicesPumpOffOnIdleAndOnSilence) {
  build();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;

  // Off on a fault and on idle for both DOPs, the analog output to its
  // value 0 (state 3): the four DOP actions and the two AOP states written,
  // the values (0 already) not.
  const sim::DopSettings off{};
  EXPECT_EQ(device().e2().dop[0], off);
  EXPECT_EQ(device().e2().dop[1], off);
  EXPECT_EQ(
      device().e2().aop,
      (sim::AopSettings{.fault_state = 3, .idle_state = 3, .fault_value = 0, .idle_value = 0}));
  EXPECT_EQ(node().counters().settings_written, 6u);
  EXPECT_EQ(wire_.safe_state_sets, 6u);
  ASSERT_TRUE(view().safe_state.has_value());
  EXPECT_EQ(*view().safe_state, cdn127::SafeState{});
  EXPECT_EQ(view().safe_state_source, SafeStateSource::kConfiguration);

  // No commander left: the idle actions, at the idle poll sent at once.
  command_all_on();
  ASSERT_TRUE(rack_->pumps().release_command(mac(kMac), now()).ok());
  EXPECT_TRUE(world().run_until([&] { return !outputs().pump_on; }, node().config().poll_period));
  EXPECT_TRUE(slave().pump().last_change_was_idle());
  EXPECT_FALSE(outputs().n2_ballast_on);
  EXPECT_EQ(outputs().analog_out_raw, 0);
  EXPECT_EQ(view().idle_reason(), "idle: no live commander");

  // The master falls silent: the device's poll connection times out after
  // 4 x EPR and it applies its fault actions.
  command_all_on();
  silence_master();
  const TimePoint silent = now();
  const Duration four_epr = 4 * node().poll_epr();
  world().run_until(silent + four_epr - node().config().poll_period - milliseconds(1));
  EXPECT_TRUE(outputs().pump_on) << "off before the device's watchdog expired";
  EXPECT_TRUE(world().run_until([&] { return !outputs().pump_on; }, silent + four_epr - now()));
  EXPECT_TRUE(slave().pump().last_change_was_fault());
  EXPECT_FALSE(outputs().n2_ballast_on);
  EXPECT_EQ(outputs().analog_out_raw, 0);
}

// The counter-proof: the same device, the pump configured to hold. Nothing
// else turns it off: neither the idle polls nor the silence.
TEST_F(SafeStateDownload, APumpConfiguredToHoldStaysOnOnIdleAndOnSilence) {
  build([](sim::SimRackConfig& c) {
    c.pumps[0].safe_state.values.pump_fault = DiscreteAction::kHold;
    c.pumps[0].safe_state.values.pump_idle = DiscreteAction::kHold;
  });
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  EXPECT_EQ(device().e2().dop[0], (sim::DopSettings{.fault_hold = true, .idle_hold = true}));
  EXPECT_EQ(device().e2().dop[1], sim::DopSettings{});
  EXPECT_EQ(node().counters().settings_written, 4u);  // DOP 2's actions, the AOP's states
  ASSERT_TRUE(view().safe_state.has_value());
  EXPECT_EQ(view().safe_state->pump_fault, DiscreteAction::kHold);
  EXPECT_EQ(view().safe_state->pump_idle, DiscreteAction::kHold);

  command_all_on();
  ASSERT_TRUE(rack_->pumps().release_command(mac(kMac), now()).ok());
  world().run_for(seconds(1));
  EXPECT_GT(node().counters().idle_polls, 5u);
  EXPECT_TRUE(outputs().pump_on);
  EXPECT_FALSE(outputs().n2_ballast_on);  // configured off: the idle actions did apply
  EXPECT_TRUE(slave().pump().last_change_was_idle());

  command_all_on();
  silence_master();
  world().run_for(4 * node().poll_epr() + seconds(1));
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kTimedOut);
  EXPECT_TRUE(outputs().pump_on);
  EXPECT_FALSE(outputs().n2_ballast_on);
  EXPECT_TRUE(slave().pump().last_change_was_fault());
}

// ---------------------------------------------------------------------------
// safe_state = "device": read, checked against the manual's ranges, kept.

class DeviceSafeState : public SafeStateRack {};

// The device's Configuration object already matches the node's (both the
// CDN127 preset): every write the start-up would make is a safe-state one,
// six for this device with the configuration's safe state (above).
TEST_F(DeviceSafeState, TheDevicesOwnActionsAreReadAndKeptNothingWritten) {
  build([](sim::SimRackConfig& c) { c.pumps[0].safe_state.source = SafeStateSource::kDevice; });
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  EXPECT_EQ(node().counters().settings_written, 0u);
  EXPECT_EQ(wire_.safe_state_sets, 0u);
  EXPECT_EQ(device().e2().dop, sim::kUnsafeFactoryOutputActions.dop);
  EXPECT_EQ(device().e2().aop, sim::kUnsafeFactoryOutputActions.aop);

  const AnalogAction hold{AnalogAction::Kind::kHold, 0};
  ASSERT_TRUE(view().safe_state.has_value());
  EXPECT_EQ(*view().safe_state,
            (cdn127::SafeState{DiscreteAction::kHold, DiscreteAction::kHold, DiscreteAction::kHold,
                               DiscreteAction::kHold, hold, hold}));
  EXPECT_EQ(view().safe_state_source, SafeStateSource::kDevice);
  EXPECT_THAT(view().safe_state_text, HasSubstr("pump: fault hold, idle hold"));
  EXPECT_THAT(view().safe_state_text, HasSubstr("analog output: fault hold, idle hold"));
}

TEST_F(DeviceSafeState, AValueOutsideTheManualsRangeIsAConfigurationFaultNeverPolled) {
  build([](sim::SimRackConfig& c) { c.pumps[0].safe_state.source = SafeStateSource::kDevice; }, {},
        [](sim::Cdn127Device& d) { d.e2().aop.fault_state = 7; });
  ASSERT_TRUE(run_until_state(NodeState::kConfigurationFault, seconds(10))) << view().reason;
  EXPECT_THAT(view().reason, HasSubstr("AOP 1.FaultState reads 07"));
  EXPECT_THAT(view().reason, HasSubstr("0..3"));
  // Re-checked, still faulted, never polled, nothing written.
  world().run_for(kTwoRechecks);
  EXPECT_EQ(view().state, NodeState::kConfigurationFault);
  EXPECT_GE(node().counters().allocate_attempts, 3u);
  EXPECT_TRUE(wire_.polls.empty());
  EXPECT_EQ(wire_.safe_state_sets, 0u);
  EXPECT_EQ(device().e2().aop.fault_state, 7);
}

// ---------------------------------------------------------------------------
// A device that refuses a safe-state attribute: configuration fault, with
// what it refused, how, and what the configuration needs; never polled.

class SafeStateRefused : public SafeStateRack {};

TEST_F(SafeStateRefused, ARefusedSetIsAConfigurationFaultNeverPolled) {
  build({}, [](sim::SlaveOptions& o) {
    o.read_only_attributes = {
        {cdn127::class_id::kAnalogOutputPoint, cdn127::aop_attr::kFaultState}};
  });
  ASSERT_TRUE(run_until_state(NodeState::kConfigurationFault, seconds(10))) << view().reason;
  EXPECT_THAT(view().reason, HasSubstr("Set AOP 1.FaultState = 03"));
  EXPECT_THAT(view().reason, HasSubstr("attribute not settable (0x0E/0xFF)"));
  EXPECT_THAT(view().reason, HasSubstr("it has 00"));
  world().run_for(kTwoRechecks);
  EXPECT_EQ(view().state, NodeState::kConfigurationFault);
  EXPECT_GE(node().counters().allocate_attempts, 3u);
  EXPECT_TRUE(wire_.polls.empty());
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
  EXPECT_EQ(device().e2().aop.fault_state, 0);
}

TEST_F(SafeStateRefused, ARefusedGetIsAConfigurationFaultNeverPolled) {
  build({}, [](sim::SlaveOptions& o) {
    o.unsupported_attributes = {
        {cdn127::class_id::kAnalogOutputPoint, cdn127::aop_attr::kFaultState}};
  });
  ASSERT_TRUE(run_until_state(NodeState::kConfigurationFault, seconds(10))) << view().reason;
  EXPECT_THAT(view().reason, HasSubstr("Get AOP 1.FaultState"));
  EXPECT_THAT(view().reason, HasSubstr("attribute not supported (0x14/0xFF)"));
  EXPECT_THAT(view().reason, HasSubstr("the configuration needs 03"));
  world().run_for(kTwoRechecks);
  EXPECT_EQ(view().state, NodeState::kConfigurationFault);
  EXPECT_TRUE(wire_.polls.empty());
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
}

// With safe_state = "device" nothing is to be written: what the node needs
// is the device's own value, in the manual's range.
TEST_F(SafeStateRefused, ARefusedGetOfTheDevicesOwnValueSaysWhatWasToBeRead) {
  build([](sim::SimRackConfig& c) { c.pumps[0].safe_state.source = SafeStateSource::kDevice; },
        [](sim::SlaveOptions& o) {
          o.unsupported_attributes = {
              {cdn127::class_id::kDiscreteOutputPoint, cdn127::dop_attr::kIdleAction}};
        });
  ASSERT_TRUE(run_until_state(NodeState::kConfigurationFault, seconds(10))) << view().reason;
  EXPECT_THAT(view().reason, HasSubstr("Get DOP 1 (pump).IdleAction"));
  EXPECT_THAT(view().reason, HasSubstr("attribute not supported (0x14/0xFF)"));
  EXPECT_THAT(view().reason, HasSubstr("1 byte(s), 0..1"));
  EXPECT_TRUE(wire_.polls.empty());
}

// ---------------------------------------------------------------------------
// Identity faults.

class IdentityFault : public SafeStateRack {};

TEST_F(IdentityFault, AMajorFaultWhileOnlineIdlesAndReleasesTheNodeUntilANewCommand) {
  build();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();

  const TimePoint fault_at = now();
  device().set_faults({.major_recoverable = true}, fault_at);
  // The device's own fault actions, as downloaded: everything off.
  EXPECT_FALSE(outputs().pump_on);
  EXPECT_TRUE(slave().pump().last_change_was_fault());
  // The keep-alive reads Identity.State and .Status in turn, once per
  // explicit EPR: either shows a major fault.
  const Duration explicit_epr = node().explicit_epr();
  ASSERT_TRUE(run_until_state(NodeState::kDeviceFault, 2 * explicit_epr)) << view().reason;
  const TimePoint faulted = view().state_since;
  EXPECT_LE(faulted - fault_at, 2 * explicit_epr);
  EXPECT_THAT(view().reason, HasSubstr("major recoverable fault"));
  EXPECT_THAT(view().reason, HasSubstr("re-checked every 3000 ms"));
  EXPECT_EQ(node().counters().reconnects, 1u);
  // One idle poll as the node leaves online, then no poll at all.
  world().run_for(milliseconds(50));
  ASSERT_GE(wire_.polls_after(faulted), 1u);
  EXPECT_EQ(wire_.polls.back().len, 0u) << "the last poll before the release was not idle";
  EXPECT_EQ(wire_.polls_after(faulted), 1u);
  EXPECT_EQ(device().owner(), devicenet::MacId::kNone) << "not released";

  // While faulted: commands refused, the device left alone, re-checked.
  EXPECT_FALSE(command(all_on()).ok());
  EXPECT_THAT(view().last_command_refused, HasSubstr("not back online"));
  const auto attempts = node().counters().allocate_attempts;
  world().run_for(kTwoRechecks);
  EXPECT_EQ(view().state, NodeState::kDeviceFault) << view().reason;
  EXPECT_GE(node().counters().allocate_attempts, attempts + 2);
  EXPECT_EQ(wire_.polls_after(faulted), 1u) << "polled while faulted";
  EXPECT_FALSE(outputs().pump_on);

  // Cleared: back online at the next re-check, idle until a new command.
  device().set_faults({}, now());
  const TimePoint cleared = now();
  note_loss();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, kFaultRecheck + kStartUp)) << view().reason;
  EXPECT_LE(view().state_since - cleared, kFaultRecheck + kStartUp);
  expect_idle_until_a_new_command();
}

TEST_F(IdentityFault, AMinorFaultIsWarnedOfAndTheNodeStaysOnlineAndCommanded) {
  build();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();
  const auto warnings = log_.warnings;

  device().set_faults({.minor_recoverable = true}, now());
  // Identity.Status is read every other keep-alive.
  const Duration explicit_epr = node().explicit_epr();
  ASSERT_TRUE(world().run_until([&] { return !view().minor_faults.empty(); },
                                2 * explicit_epr + node().config().poll_period));
  EXPECT_THAT(view().minor_faults, HasSubstr("minor recoverable fault"));
  EXPECT_EQ(log_.warnings, warnings + 1);
  EXPECT_THAT(log_.last_warning, HasSubstr("minor recoverable fault"));

  world().run_for(seconds(5));
  EXPECT_EQ(view().state, NodeState::kOnline) << view().reason;
  EXPECT_EQ(node().counters().reconnects, 0u);
  EXPECT_EQ(outputs(), all_on());
  EXPECT_TRUE(view().outputs_requested.has_value());
  EXPECT_EQ(log_.warnings, warnings + 1) << "warned of more than once: " << log_.last_warning;
}

TEST_F(IdentityFault, AMajorFaultAtStartUpIsNeverOnlineNorPolledUntilCleared) {
  build({}, {},
        [](sim::Cdn127Device& d) { d.set_faults({.major_recoverable = true}, TimePoint{}); });
  ASSERT_TRUE(run_until_state(NodeState::kDeviceFault, seconds(10))) << view().reason;
  EXPECT_THAT(view().reason, HasSubstr("major recoverable fault"));
  world().run_for(kTwoRechecks);
  EXPECT_EQ(view().state, NodeState::kDeviceFault);
  EXPECT_GE(node().counters().allocate_attempts, 3u);
  for (const auto& t : events_.of(mac(kMac))) EXPECT_NE(t.to, NodeState::kOnline) << t.reason;
  EXPECT_TRUE(wire_.polls.empty());
  EXPECT_EQ(slave().poll_state(), sim::ConnectionState::kNonExistent);
  // A command while the device is faulted is refused: the fault may clear
  // long after it was given.
  EXPECT_FALSE(command(all_on()).ok());
  EXPECT_THAT(view().last_command_refused, HasSubstr("not back online"));

  // Cleared: online by the next re-check and a start-up, idle.
  device().set_faults({}, now());
  const TimePoint cleared = now();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, kFaultRecheck + kStartUp)) << view().reason;
  EXPECT_LE(view().state_since - cleared, kFaultRecheck + kStartUp);
  EXPECT_EQ(view().idle_reason(), "idle: waiting for a new command after reconnection");
  world().run_for(seconds(1));
  EXPECT_FALSE(outputs().pump_on);
  EXPECT_TRUE(command(all_on()).ok());
  world().run_for(milliseconds(200));
  EXPECT_TRUE(outputs().pump_on);
}

// ---------------------------------------------------------------------------
// The bus lost under a commanded pump: the port loop calls recheck_mac when
// the bus is back (bus-off recovered, the interface up again).

struct Outage {
  const char* name;
  Duration length;  // the master off the bus
  const char* why;  // what the port loop tells the scanner
};

void PrintTo(const Outage& o, std::ostream* os) { *os << o.name; }

class BusLoss : public SafeStateRack, public ::testing::WithParamInterface<Outage> {};

TEST_P(BusLoss, ThePumpComesBackIdleAndStaysOffUntilANewCommand) {
  build();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();

  silence_master();
  world().run_for(GetParam().length);
  unsilence_master();
  rack_->scanner().recheck_mac(GetParam().why, now());
  EXPECT_NE(view().state, NodeState::kOnline);
  EXPECT_FALSE(command(all_on()).ok()) << "a command while the node is away";
  EXPECT_THAT(view().last_command_refused, HasSubstr("not back online"));

  note_loss();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(20))) << view().reason;
  EXPECT_EQ(node().counters().reconnects, 1u);
  expect_idle_until_a_new_command();
}

// A bus lost for less than the device's own timeout less the MAC check: the
// poll connection outlives it, still carrying every output on. The master
// finds it at the next start-up and releases it; a device that keeps its
// outputs on a Release (the strict reading: the manual names no action)
// must have been polled idle first, or it would run the pump on until the
// new connection idles it, and for good if the start-up then stopped at a
// fault.
TEST_F(SafeStateRack, AConnectionLeftFromBeforeTheLossIsPolledIdleBeforeItsRelease) {
  build([](sim::SimRackConfig& c) { c.pumps[0].node.expected_packet_rate = seconds(2); },
        [](sim::SlaveOptions& o) { o.release_keeps_outputs = true; });
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();

  silence_master();
  world().run_for(milliseconds(300));
  unsilence_master();
  bool released = false;
  world().bus().set_tap([&](const sim::WireFrame& f) {
    count(f);
    const auto& d = f.frame.data;
    // [hdr][4C Release][03 DeviceNet][01][choice]: the poll connection's.
    released =
        released ||
        (f.frame.id == devicenet::group2_id(
                           mac(kMac), devicenet::Group2Message::kUnconnectedExplicitRequest) &&
         f.frame.len == 5 && d[1] == 0x4C && (d[4] & 0x02) != 0);
  });
  rack_->scanner().recheck_mac("bus-off recovered", now());
  note_loss();
  ASSERT_TRUE(world().run_until([&] { return released; }, seconds(10)));
  world().run_for(milliseconds(2));
  EXPECT_NE(view().state, NodeState::kOnline) << "still starting up";
  EXPECT_FALSE(outputs().pump_on) << "the stale connection was released with the pump on";
  EXPECT_FALSE(outputs().n2_ballast_on);

  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(20))) << view().reason;
  expect_idle_until_a_new_command();
}

// A node taken out of the configuration while the master is off the bus: its
// idle poll on leaving is lost with the bus, and its device, whose timeout
// outlasts the loss, still runs the pump. Once the master is back it is
// released, and polled idle first.
TEST_F(SafeStateRack, ANodeTakenOutDuringABusLossIsPolledIdleBeforeItsRelease) {
  build([](sim::SimRackConfig& c) { c.pumps[0].node.expected_packet_rate = seconds(2); },
        [](sim::SlaveOptions& o) { o.release_keeps_outputs = true; });
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();

  silence_master();
  (void)rack_->port().reconfigure(rack_->scanner().config(),
                                  rack::PortNodes(std::vector<rack::PumpConfig>{}), now());
  ASSERT_EQ(rack_->scanner().nodes_leaving(), 1u);
  world().run_for(milliseconds(300));
  unsilence_master();
  rack_->scanner().recheck_mac("bus-off recovered", now());
  ASSERT_TRUE(
      world().run_until([&] { return rack_->scanner().nodes_leaving() == 0; }, seconds(10)));
  world().run_for(milliseconds(2));
  EXPECT_FALSE(outputs().pump_on) << "released with the pump on";
  EXPECT_FALSE(outputs().n2_ballast_on);
}

INSTANTIATE_TEST_SUITE_P(Outages, BusLoss,
                         ::testing::Values(
                             // Shorter than the device's 4 x EPR: its connection outlives the
                             // outage, the MAC check (2 s of silence) does not.
                             Outage{"BusOffRecovered", milliseconds(300), "bus-off recovered"},
                             // Longer: the device has timed out and the master lost the node.
                             Outage{"InterfaceDownAndUpAgain", seconds(3),
                                    "the interface is up again"}),
                         [](const ::testing::TestParamInfo<Outage>& p) { return p.param.name; });

}  // namespace
}  // namespace dnbridge::test

namespace dnbridge::test {
namespace {

// A command given before the node is online is refused, not kept: a pump
// must never start when its device comes, perhaps hours later.
TEST_F(IdentityFault, ACommandBeforeTheNodeIsFirstOnlineIsRefused) {
  build();
  EXPECT_NE(view().state, NodeState::kOnline);
  EXPECT_FALSE(command(all_on()).ok());
  EXPECT_THAT(view().last_command_refused, HasSubstr("not online"));
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  world().run_for(seconds(1));
  EXPECT_FALSE(outputs().pump_on);
  EXPECT_EQ(view().idle_reason(), "idle: no command yet");
  EXPECT_EQ(node().counters().polls, node().counters().idle_polls);
  command_all_on();
}

// resume = "last-command" does not reach across a device fault: the fault
// may clear long after the command was given.
TEST_F(IdentityFault, ADeviceFaultVoidsTheCommandEvenWithResumeLastCommand) {
  build([](sim::SimRackConfig& c) { c.pumps[0].resume = rack::ResumePolicy::kLastCommand; });
  ASSERT_TRUE(run_until_state(NodeState::kOnline, seconds(10))) << view().reason;
  command_all_on();
  device().set_faults({.major_recoverable = true}, now());
  ASSERT_TRUE(run_until_state(NodeState::kDeviceFault, 2 * node().explicit_epr())) << view().reason;
  device().set_faults({}, now());
  note_loss();
  ASSERT_TRUE(run_until_state(NodeState::kOnline, kFaultRecheck + kStartUp)) << view().reason;
  expect_idle_until_a_new_command();
}

}  // namespace
}  // namespace dnbridge::test
