// The master against simulated CDN127s on the in-process bus, on a fake
// clock: the main proof that the scanner does what a scanner must.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "bridge/cip/data_types.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "bridge/profiles/cdn127/device_info.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::group2_id;
using devicenet::Group2Message;
using devicenet::PortState;
using devicenet::RequestMessage;
using ::testing::HasSubstr;

class MasterSlave : public ::testing::Test {
 protected:
  void build(sim::SimRackConfig config) {
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->observe(events_);
  }
  sim::SimRack& rack() { return *rack_; }
  TimePoint now() { return rack_->now(); }
  const rack::PumpView& view(unsigned m) { return *rack_->pumps().pump(mac(m)); }
  const devicenet::Node& node(unsigned m) { return *rack_->scanner().node(mac(m)); }
  sim::Cdn127Slave& device(unsigned m) { return rack_->device(mac(m)).device(); }

  bool run_until_online(Duration timeout = seconds(30)) {
    return rack_->world().run_until([&] { return rack_->all_online(); }, timeout);
  }

  // Submits an explicit request and runs until its result arrives.
  const EventRecorder::ExplicitDone* explicit_request(unsigned m, RequestMessage request) {
    auto id = rack_->scanner().request_explicit(mac(m), request, now());
    EXPECT_TRUE(id.ok()) << id.error().message();
    if (!id) return nullptr;
    rack_->world().run_until([&] { return events_.result(*id) != nullptr; }, seconds(10));
    return events_.result(*id);
  }

  static RequestMessage get(std::uint16_t cls, std::uint16_t inst, std::uint8_t attr) {
    RequestMessage r;
    r.service = cip::code(cip::Service::kGetAttributeSingle);
    r.class_id = cls;
    r.instance_id = inst;
    r.attribute = attr;
    return r;
  }
  static RequestMessage set(std::uint16_t cls, std::uint16_t inst, std::uint8_t attr, Bytes data) {
    RequestMessage r = get(cls, inst, attr);
    r.service = cip::code(cip::Service::kSetAttributeSingle);
    r.data = data;
    return r;
  }

  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
};

TEST_F(MasterSlave, SixtyThreeNodesOnOnePortComeOnline) {
  std::vector<unsigned> macs;
  for (unsigned m = 1; m <= 63; ++m) macs.push_back(m);
  build(rack_config(macs, 0));
  rack().start();
  ASSERT_TRUE(run_until_online(seconds(30)));
  for (unsigned m : macs) {
    const auto& v = view(m);
    EXPECT_EQ(v.state, NodeState::kOnline) << m << ": " << v.reason;
    EXPECT_EQ(v.identity.vendor_id, cdn127::kVendorId);
    EXPECT_EQ(v.identity.product_code, cdn127::kProductCode);
    EXPECT_EQ(v.identity.product_name, "CDN127");  // a fragmented response
    EXPECT_EQ(device(m).owner(), 0u);
  }
  // Every node then stays online and is polled at its period.
  const auto polls_before = node(33).counters().responses;
  rack().world().run_for(seconds(10));
  for (unsigned m : macs) {
    EXPECT_EQ(view(m).state, NodeState::kOnline) << m;
    // A clean bus: every poll answered, nothing malformed.
    EXPECT_EQ(node(m).counters().timeouts, 0u) << m;
    EXPECT_EQ(node(m).counters().errors, 0u) << m;
  }
  EXPECT_NEAR(static_cast<double>(node(33).counters().responses - polls_before), 100.0, 2.0);
  EXPECT_EQ(node(33).counters().reconnects, 0u);
}

TEST_F(MasterSlave, LifeCycleGoesThroughEveryStepWithReasons) {
  build(rack_config({12}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  std::vector<NodeState> states;
  for (const auto& t : events_.of(mac(12))) {
    states.push_back(t.to);
    EXPECT_FALSE(t.reason.empty());
  }
  const std::vector<NodeState> expected{NodeState::kAbsent, NodeState::kIdentifying,
                                        NodeState::kConfiguring, NodeState::kVerifying,
                                        NodeState::kOnline};
  EXPECT_EQ(states, expected);
  EXPECT_EQ(std::vector<PortState>(events_.port_states.begin(), events_.port_states.end()),
            (std::vector<PortState>{PortState::kCheckingMac, PortState::kRunning}));
  // The master checked its own MAC for 2 s before it allocated anything.
  EXPECT_GE(events_.of(mac(12)).at(1).at - TimePoint{}, seconds(3) - milliseconds(1));
}

TEST_F(MasterSlave, OutputsAndInputsRoundTrip) {
  build(rack_config({7}));
  rack().start();
  ASSERT_TRUE(run_until_online());

  cdn127::PumpOutputs out;
  out.pump_on = true;
  out.n2_ballast_on = true;
  out.analog_out_raw = 2048;
  ASSERT_TRUE(rack().pumps().command(mac(7), out, now()).ok());
  rack().world().run_for(milliseconds(5));  // immediate poll on change
  EXPECT_EQ(device(7).outputs(), out);
  EXPECT_FALSE(view(7).outputs_idle);
  EXPECT_EQ(view(7).outputs_applied, out);

  // The pump spins up, then the inputs come back with their meaning.
  auto& pump_model = device(7).pump();
  pump_model.set_analog_input(0, 1000);
  pump_model.set_analog_input(1, 4095);
  rack().world().run_for(seconds(6));
  const auto& v = view(7);
  ASSERT_TRUE(v.has_inputs);
  ASSERT_TRUE(v.inputs.pump.has_value());
  EXPECT_TRUE(v.inputs.pump->pump_running);
  EXPECT_TRUE(v.inputs.pump->interlock_ok);
  EXPECT_FALSE(v.inputs.pump->alarm_active);
  EXPECT_EQ(v.inputs.analog_inputs_raw[0], 1000);
  EXPECT_EQ(v.inputs.analog_inputs_raw[1], 4095);

  pump_model.set_alarm(true, now());
  rack().world().run_for(milliseconds(300));
  EXPECT_TRUE(view(7).inputs.pump->alarm_active);
  ASSERT_TRUE(view(7).inputs.exception_status.has_value());
  EXPECT_TRUE(view(7).inputs.exception_status->alarm_device_specific);
}

TEST_F(MasterSlave, OutOfRangeAnalogOutputIsRefusedNotClipped) {
  build(rack_config({7}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  cdn127::PumpOutputs out;
  out.analog_out_raw = 4096;
  auto s = rack().pumps().command(mac(7), out, now());
  EXPECT_EQ(s.error(), Errc::kOutOfRange);
  rack().world().run_for(milliseconds(500));
  EXPECT_EQ(device(7).outputs().analog_out_raw, 0);
}

TEST_F(MasterSlave, ChangedOutputsGoOutAtOnceNotOnTheNextPeriod) {
  build(rack_config({7}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  rack().world().run_for(milliseconds(30));  // between two polls
  const auto polls = node(7).counters().polls;
  cdn127::PumpOutputs out;
  out.pump_on = true;
  ASSERT_TRUE(rack().pumps().command(mac(7), out, now()).ok());
  rack().world().run_for(milliseconds(1));
  EXPECT_EQ(node(7).counters().polls, polls + 1);
  EXPECT_TRUE(device(7).outputs().pump_on);
}

// A power-cycled node comes back by itself, idle: the command given before
// the loss was for the device as it was then. A command sent while it is
// away is refused; one after its return applies.
TEST_F(MasterSlave, PowerCycledNodeComesBackIdleUntilANewCommand) {
  build(rack_config({5, 6}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  cdn127::PumpOutputs out;
  out.pump_on = true;
  ASSERT_TRUE(rack().pumps().command(mac(5), out, now()).ok());
  ASSERT_TRUE(rack().pumps().command(mac(6), out, now()).ok());
  rack().world().run_for(seconds(1));
  ASSERT_TRUE(device(5).outputs().pump_on);

  device(5).power_cycle(now());
  EXPECT_FALSE(device(5).outputs().pump_on);  // a device powers up with its outputs off
  rack().world().run_for(milliseconds(50));
  EXPECT_NE(view(5).state, NodeState::kOnline);
  // The same command again while the node is away: refused, not kept.
  EXPECT_FALSE(rack().pumps().command(mac(5), out, now()).ok());
  EXPECT_THAT(view(5).last_command_refused, HasSubstr("not back online"));
  ASSERT_TRUE(run_until_online(seconds(20)));
  rack().world().run_for(seconds(2));
  // Back online, idle: nothing of the old command is applied.
  EXPECT_FALSE(device(5).outputs().pump_on);
  EXPECT_TRUE(view(5).outputs_idle);
  EXPECT_EQ(view(5).idle_reason(), "idle: waiting for a new command after reconnection");
  EXPECT_EQ(node(5).counters().reconnects, 1u);
  // The neighbour, never lost, keeps its command.
  EXPECT_TRUE(device(6).outputs().pump_on);
  EXPECT_EQ(node(6).counters().reconnects, 0u);

  // A command after the return: applied.
  ASSERT_TRUE(rack().pumps().command(mac(5), out, now()).ok());
  rack().world().run_for(milliseconds(200));
  EXPECT_TRUE(device(5).outputs().pump_on);
  EXPECT_FALSE(view(5).outputs_idle);
  EXPECT_EQ(view(5).idle_reason(), "");
}

// resume = "last-command": the opt-in to drive the last outputs again after
// a loss (unsafe: a pump may start on its own after a power cycle).
TEST_F(MasterSlave, ResumeLastCommandDrivesTheLastOutputsAgainAfterAPowerCycle) {
  auto config = rack_config({5});
  config.pumps[0].resume = rack::ResumePolicy::kLastCommand;
  build(std::move(config));
  rack().start();
  ASSERT_TRUE(run_until_online());
  cdn127::PumpOutputs out;
  out.pump_on = true;
  ASSERT_TRUE(rack().pumps().command(mac(5), out, now()).ok());
  rack().world().run_for(seconds(1));

  device(5).power_cycle(now());
  EXPECT_FALSE(device(5).outputs().pump_on);
  rack().world().run_for(milliseconds(50));
  ASSERT_TRUE(run_until_online(seconds(20)));
  rack().world().run_for(milliseconds(200));
  EXPECT_TRUE(device(5).outputs().pump_on);
  EXPECT_EQ(node(5).counters().reconnects, 1u);
}

TEST_F(MasterSlave, DisconnectedNodeIsDroppedAfterFourEprAndReturns) {
  build(rack_config({9}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  const TimePoint cut = now();
  rack().device(mac(9)).disconnect();
  rack().world().run_until([&] { return view(9).state == NodeState::kAbsent; }, seconds(5));
  ASSERT_EQ(view(9).state, NodeState::kAbsent);
  // EPR 500 ms: silence for 4 x 500 ms, give or take one poll period.
  EXPECT_GE(view(9).state_since - cut, milliseconds(1900));
  EXPECT_LE(view(9).state_since - cut, milliseconds(2100));
  EXPECT_NE(view(9).reason.find("4 x EPR"), std::string::npos) << view(9).reason;
  rack().world().run_for(seconds(3));
  rack().device(mac(9)).reconnect();
  ASSERT_TRUE(run_until_online(seconds(20)));
}

TEST_F(MasterSlave, NodeOwnedByAnotherMasterIsReportedAsSuch) {
  auto config = rack_config({12});
  config.port.fault_recheck = seconds(3);
  build(config);
  // Another master (MAC 5) holds node 12 first.
  EventRecorder other_events;
  rack::PumpRack other_rack({pump(12)});
  devicenet::ScannerConfig other_port;
  other_port.master_mac = mac(5);
  sim::SimMaster other(rack().world(), rack::PumpRack::scanner_config(other_port, {pump(12)}),
                       other_rack);
  other_rack.attach(other.scanner());
  rack().device(mac(12)).power_on(now());
  other.scanner().start(now());
  rack().world().run_until([&] { return other_rack.pump(mac(12))->online; }, seconds(10));
  ASSERT_TRUE(other_rack.pump(mac(12))->online);

  rack().start();
  rack().world().run_until([&] { return view(12).state == NodeState::kOwnedByOtherMaster; },
                           seconds(10));
  EXPECT_EQ(view(12).state, NodeState::kOwnedByOtherMaster);
  EXPECT_NE(view(12).reason.find("0x0C/0x01"), std::string::npos) << view(12).reason;
  EXPECT_EQ(node(12).counters().polls, 0u);
  EXPECT_EQ(device(12).owner(), 5u);

  // When the other master lets go, this one takes the node at its re-check.
  other.scanner().stop(now());
  ASSERT_TRUE(run_until_online(seconds(10)));
  EXPECT_EQ(device(12).owner(), 0u);
}

TEST_F(MasterSlave, WrongIdentityIsAFaultAndNeverPolled) {
  auto config = rack_config({20, 21});
  config.pumps[0].identity = devicenet::ExpectedIdentity{59, 27, 1777};
  build(config);
  rack().start();
  rack().world().run_until(
      [&] { return view(21).online && view(20).state == NodeState::kWrongDevice; }, seconds(20));
  EXPECT_EQ(view(20).state, NodeState::kWrongDevice);
  EXPECT_NE(view(20).reason.find("product code 1777"), std::string::npos) << view(20).reason;
  EXPECT_NE(view(20).reason.find("product code 1888"), std::string::npos) << view(20).reason;
  rack().world().run_for(seconds(30));  // several re-checks
  EXPECT_EQ(view(20).state, NodeState::kWrongDevice);
  EXPECT_EQ(rack().world().bus().frames_with_id(group2_id(mac(20), Group2Message::kMasterIoPoll)),
            0u);
  EXPECT_EQ(node(20).counters().polls, 0u);
  // Re-checks do not repeat the transition.
  EXPECT_EQ(events_.of(mac(20)).back().to, NodeState::kWrongDevice);
  std::size_t wrong = 0;
  for (const auto& t : events_.of(mac(20))) wrong += t.to == NodeState::kWrongDevice;
  EXPECT_EQ(wrong, 1u);
  // The device is left unowned, not held by a master that will not poll it.
  EXPECT_EQ(device(20).owner(), devicenet::MacId::kNone);
}

TEST_F(MasterSlave, SizeMismatchIsAConfigurationFaultShowingBoth) {
  auto config = rack_config({14});
  // Expect one byte more than the device will produce: the master must say
  // so and not poll.
  config.adjust_scan_list = [](devicenet::ScannerConfig& port) {
    port.nodes.at(0).profile.produced_size += 1;
  };
  build(config);
  rack().start();
  rack().world().run_until([&] { return view(14).state == NodeState::kConfigurationFault; },
                           seconds(10));
  EXPECT_EQ(view(14).state, NodeState::kConfigurationFault);
  EXPECT_NE(view(14).reason.find("produces 6 B"), std::string::npos) << view(14).reason;
  EXPECT_NE(view(14).reason.find("expects 7 B"), std::string::npos) << view(14).reason;
  EXPECT_EQ(node(14).counters().polls, 0u);
}

TEST_F(MasterSlave, DeviceConfigurationIsMadeToMatchTheScanList) {
  auto config = rack_config({15});
  config.pumps[0].io = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);
  build(config);
  rack().start();
  ASSERT_TRUE(run_until_online());
  EXPECT_EQ(device(15).device().configuration(),
            cdn127::preset(cdn127::ConfigurationPreset::kCdn118));
  EXPECT_EQ(node(15).config().profile.produced_size, 2u);
  EXPECT_EQ(node(15).config().profile.consumed_size, 3u);
  cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 100;
  ASSERT_TRUE(rack().pumps().command(mac(15), out, now()).ok());
  rack().world().run_for(milliseconds(200));
  EXPECT_EQ(device(15).outputs(), out);
  EXPECT_FALSE(view(15).inputs.analog_inputs_raw[0].has_value());
}

TEST_F(MasterSlave, MasterSilencePastFourEprMakesTheDeviceApplyItsFaultActions) {
  build(rack_config({3}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  // Fault actions: pump output to its fault value (off), analog output to 1234.
  const std::array<std::uint8_t, 1> fault_state{3};
  const std::array<std::uint8_t, 2> fault_value{0xD2, 0x04};
  ASSERT_TRUE(explicit_request(3, set(cdn127::class_id::kAnalogOutputPoint, 1,
                                      cdn127::aop_attr::kFaultState, Bytes(fault_state)))
                  ->result.ok());
  ASSERT_TRUE(explicit_request(3, set(cdn127::class_id::kAnalogOutputPoint, 1,
                                      cdn127::aop_attr::kFaultValue, Bytes(fault_value)))
                  ->result.ok());
  cdn127::PumpOutputs out;
  out.pump_on = true;
  out.analog_out_raw = 3000;
  ASSERT_TRUE(rack().pumps().command(mac(3), out, now()).ok());
  rack().world().run_for(milliseconds(300));
  ASSERT_TRUE(device(3).outputs().pump_on);

  // The master goes silent (its process died, its cable was pulled).
  (void)rack().world().bus().detach(rack().master().handle());
  const TimePoint silent = now();
  rack().world().run_until(silent + milliseconds(1800));
  EXPECT_TRUE(device(3).outputs().pump_on) << "fault action before 4 x EPR";
  rack().world().run_until(silent + milliseconds(2200));
  EXPECT_FALSE(device(3).outputs().pump_on);
  EXPECT_EQ(device(3).outputs().analog_out_raw, 1234);
  EXPECT_TRUE(device(3).pump().last_change_was_fault());
}

TEST_F(MasterSlave, IdlePollMakesTheDeviceApplyItsIdleActions) {
  build(rack_config({4}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  const std::array<std::uint8_t, 1> idle_state{3};
  const std::array<std::uint8_t, 2> idle_value{0x64, 0x00};  // 100
  ASSERT_TRUE(explicit_request(4, set(cdn127::class_id::kAnalogOutputPoint, 1,
                                      cdn127::aop_attr::kIdleState, Bytes(idle_state)))
                  ->result.ok());
  ASSERT_TRUE(explicit_request(4, set(cdn127::class_id::kAnalogOutputPoint, 1,
                                      cdn127::aop_attr::kIdleValue, Bytes(idle_value)))
                  ->result.ok());
  cdn127::PumpOutputs out;
  out.pump_on = true;
  out.n2_ballast_on = true;
  out.analog_out_raw = 4000;
  ASSERT_TRUE(rack().pumps().command(mac(4), out, now()).ok());
  rack().world().run_for(milliseconds(300));
  ASSERT_EQ(device(4).outputs(), out);

  // No commander left: the master polls with zero bytes.
  ASSERT_TRUE(rack().pumps().release_command(mac(4), now()).ok());
  rack().world().run_for(milliseconds(300));
  EXPECT_FALSE(device(4).outputs().pump_on);
  EXPECT_FALSE(device(4).outputs().n2_ballast_on);
  EXPECT_EQ(device(4).outputs().analog_out_raw, 100);
  EXPECT_TRUE(device(4).pump().last_change_was_idle());
  EXPECT_TRUE(view(4).outputs_idle);
  EXPECT_GT(node(4).counters().idle_polls, 0u);
  // Idle is not a fault: the node stays online.
  EXPECT_EQ(view(4).state, NodeState::kOnline);
}

TEST_F(MasterSlave, DeviceSupervisorStringsAreReadThroughFragmentation) {
  build(rack_config({8}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  struct Expected {
    std::uint8_t attribute;
    const char* text;
  };
  for (const Expected& e : {Expected{cdn127::supervisor_attr::kManufacturerType, "ANALOG IO"},
                            Expected{cdn127::supervisor_attr::kSemiRevisionLevel, "E00-0000"},
                            Expected{cdn127::supervisor_attr::kManufacturerName, "D.I.P. Inc."},
                            Expected{cdn127::supervisor_attr::kManufacturerModel, "CDN127"}}) {
    const auto* done =
        explicit_request(8, get(cdn127::class_id::kDeviceSupervisor, 1, e.attribute));
    ASSERT_NE(done, nullptr);
    ASSERT_TRUE(done->result.ok()) << done->result.error.message();
    auto text = cip::decode_short_string(done->result.data.view());
    ASSERT_TRUE(text.ok());
    EXPECT_EQ(cip::trim_padding(*text), e.text);
    // More than the 6 data bytes an unfragmented response can carry.
    EXPECT_GT(done->result.data.size(), 6u);
  }
}

TEST_F(MasterSlave, ExceptionAndWarningDetailAreReadAndDecoded) {
  build(rack_config({8}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  device(8).pump().set_n2_flow_ok(false);
  device(8).pump().set_warning(true);
  rack().world().run_for(milliseconds(200));

  const auto* exception = explicit_request(
      8, get(cdn127::class_id::kDeviceSupervisor, 1, cdn127::supervisor_attr::kExceptionDetail));
  ASSERT_NE(exception, nullptr);
  ASSERT_TRUE(exception->result.ok()) << exception->result.error.message();
  auto detail = cdn127::decode_exception_detail(exception->result.data.view());
  ASSERT_TRUE(detail.ok()) << detail.error().message();
  // The manual's structure: DIP 8, DOP 8, AIP 2, AOP 1 status bits.
  ASSERT_EQ(detail->point_count, 4u);
  EXPECT_EQ(detail->points[cdn127::SupervisorDetail::kDip].count, 8u);
  EXPECT_EQ(detail->points[cdn127::SupervisorDetail::kDop].count, 8u);
  EXPECT_EQ(detail->points[cdn127::SupervisorDetail::kAip].count, 2u);
  EXPECT_EQ(detail->points[cdn127::SupervisorDetail::kAop].count, 1u);

  const auto* warning = explicit_request(
      8, get(cdn127::class_id::kDeviceSupervisor, 1, cdn127::supervisor_attr::kWarningDetail));
  ASSERT_NE(warning, nullptr);
  ASSERT_TRUE(warning->result.ok());
  auto warnings = cdn127::decode_warning_detail(warning->result.data.view());
  ASSERT_TRUE(warnings.ok());
  EXPECT_EQ(warnings->point_count, 0u);
  // What the poll's exception byte says agrees.
  ASSERT_TRUE(view(8).inputs.exception_status.has_value());
  EXPECT_TRUE(view(8).inputs.exception_status->alarm_device_specific);
  EXPECT_TRUE(view(8).inputs.exception_status->warning_device_specific);
}

TEST_F(MasterSlave, ExplicitErrorsComeBackAsData) {
  build(rack_config({8}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  const auto* done = explicit_request(8, get(cdn127::class_id::kIdentity, 1, 99));
  ASSERT_NE(done, nullptr);
  EXPECT_EQ(done->result.error, Errc::kDeviceError);
  EXPECT_EQ(done->result.general_status, cip::GeneralStatus::kAttributeNotSupported);
  // The node is not disturbed by a refused request.
  EXPECT_EQ(view(8).state, NodeState::kOnline);
}

TEST_F(MasterSlave, FivePercentFrameLossKeepsEveryNodeOnline) {
  std::vector<unsigned> macs;
  for (unsigned m = 1; m <= 20; ++m) macs.push_back(m);
  build(rack_config(macs));
  sim::FaultRule loss;
  loss.mask = 0;  // every frame
  loss.action = sim::FaultAction::kDrop;
  loss.rate = 0.05;
  rack().world().bus().faults().add(loss);
  rack().start();
  ASSERT_TRUE(run_until_online(seconds(60)));
  rack().world().run_for(seconds(60));
  std::uint64_t timeouts = 0;
  for (unsigned m : macs) {
    EXPECT_EQ(view(m).state, NodeState::kOnline) << m << ": " << view(m).reason;
    EXPECT_EQ(node(m).counters().reconnects, 0u) << m;
    timeouts += node(m).counters().timeouts;
  }
  EXPECT_GT(timeouts, 0u);  // the loss was real
  EXPECT_GT(rack().world().bus().stats().fault_dropped, 1000u);
}

TEST_F(MasterSlave, AnotherNodeWithTheMastersMacStopsThePort) {
  auto config = rack_config({10}, 30);
  build(config);
  // A CDN127 already online at MAC 30, the master's own.
  auto& intruder = rack().add_device(sim::default_slave_options(mac(30)), now());
  rack().world().run_for(seconds(3));
  ASSERT_EQ(intruder.device().network_state(), sim::Cdn127Slave::NetworkState::kOnline);
  rack().start();
  rack().world().run_for(seconds(5));
  EXPECT_EQ(rack().scanner().state(), PortState::kDuplicateMac);
  EXPECT_NE(events_.port_reason.find("MAC 30"), std::string::npos) << events_.port_reason;
  EXPECT_EQ(node(10).counters().allocate_attempts, 0u);
  EXPECT_EQ(rack().world().bus().frames_with_id(
                group2_id(mac(10), Group2Message::kUnconnectedExplicitRequest)),
            0u);
}

TEST_F(MasterSlave, OnlineMasterDefendsItsMac) {
  build(rack_config({10}, 30));
  rack().start();
  ASSERT_TRUE(run_until_online());
  // A device set to the master's MAC is powered up on the running network:
  // the master answers its check, and the newcomer goes silent.
  auto& intruder = rack().add_device(sim::default_slave_options(mac(30)), now());
  rack().world().run_for(seconds(3));
  EXPECT_EQ(intruder.device().network_state(), sim::Cdn127Slave::NetworkState::kCommunicationFault);
  EXPECT_EQ(rack().scanner().state(), PortState::kRunning);
  EXPECT_EQ(view(10).state, NodeState::kOnline);
}

TEST_F(MasterSlave, OrderlyShutdownIdlesThenReleasesEveryNode) {
  build(rack_config({1, 2, 3}));
  rack().start();
  ASSERT_TRUE(run_until_online());
  cdn127::PumpOutputs out;
  out.pump_on = true;
  for (unsigned m : {1u, 2u, 3u}) ASSERT_TRUE(rack().pumps().command(mac(m), out, now()).ok());
  rack().world().run_for(milliseconds(300));
  // Stop while some polls are outstanding: their answers come first, then
  // one idle poll each, then the Release.
  rack().world().run_until([&] { return node(2).counters().polls > node(2).counters().responses; },
                           seconds(1));
  rack().scanner().stop(now());
  rack().world().run_until([&] { return rack().scanner().stopped(); }, seconds(5));
  EXPECT_EQ(rack().scanner().state(), PortState::kStopped);
  for (unsigned m : {1u, 2u, 3u}) {
    EXPECT_EQ(view(m).state, NodeState::kStopped);
    EXPECT_FALSE(device(m).outputs().pump_on) << m;  // idle action: off
    EXPECT_TRUE(device(m).pump().last_change_was_idle()) << m;
    EXPECT_EQ(device(m).owner(), devicenet::MacId::kNone) << m;
    EXPECT_EQ(node(m).counters().errors, 0u) << m;  // never two polls outstanding
    EXPECT_EQ(node(m).counters().polls, node(m).counters().responses) << m;
  }
}

TEST_F(MasterSlave, PollsOfNodesWithOnePeriodAreSpreadOverIt) {
  std::vector<unsigned> macs;
  for (unsigned m = 1; m <= 10; ++m) macs.push_back(m);
  build(rack_config(macs));
  rack().start();
  ASSERT_TRUE(run_until_online());
  // Count polls in each 10 ms slice of one 100 ms period.
  std::array<std::uint64_t, 10> per_slice{};
  std::vector<std::uint64_t> last(11);
  for (unsigned m : macs) last[m] = node(m).counters().polls;
  for (int slice = 0; slice < 10; ++slice) {
    rack().world().run_for(milliseconds(10));
    for (unsigned m : macs) {
      per_slice[static_cast<std::size_t>(slice)] += node(m).counters().polls - last[m];
      last[m] = node(m).counters().polls;
    }
  }
  for (auto n : per_slice) EXPECT_LE(n, 2u);
}

}  // namespace
}  // namespace dnbridge::test
