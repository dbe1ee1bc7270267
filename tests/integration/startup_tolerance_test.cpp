// The master comes online with a CDN127 of every reading of its manual that
// field devices took, one reading at a time and all of them together: the
// simulated device behaves as that reading (sim::SlaveOptions), and the
// master must bring it online with exactly one allocation of each
// connection, keep it online for 100 polls and more, and apply a command.
// Master and simulated devices on the in-process bus, fake clock.
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <string>

#include "bridge/cip/epath.hpp"
#include "bridge/devicenet/wire/identifier.hpp"
#include "rack_fixture.hpp"

namespace dnbridge::test {
namespace {

constexpr unsigned kMac = 12;
namespace cdn127 = profiles::cdn127;

// The Connection 2 paths the CDN127 profile asks for (assemblies 103 and
// 104), in the 16-bit logical segment form: the same paths, spelled so that
// they differ byte for byte from what the device reports (8-bit form). A
// master that compares first then writes them, and a device whose paths are
// fixed refuses: what it has serves all the same.
const std::vector<std::uint8_t> kProducedPath16 = {0x21, 0x00, 0x04, 0x00, 0x25,
                                                   0x00, 103,  0x00, 0x30, 0x03};
const std::vector<std::uint8_t> kConsumedPath16 = {0x21, 0x00, 0x04, 0x00, 0x25,
                                                   0x00, 104,  0x00, 0x30, 0x03};

// A reading: what it does to the device, and what to the scan list.
struct Reading {
  std::string name;
  std::function<void(sim::SlaveOptions&)> device;
  std::function<void(devicenet::NodeConfig&)> node = {};
};

void PrintTo(const Reading& r, std::ostream* os) { *os << r.name; }

// What the master sent and got on the wire, for one node.
struct Wire {
  unsigned allocate_explicit = 0;
  unsigned allocate_poll = 0;
  unsigned path_sets = 0;           // Set of Connection 2 attribute 14 or 16 (first fragments too)
  unsigned configuration_sets = 0;  // Set to the Configuration object (class 0x40)
  std::vector<std::uint8_t> no_nc_mask_set;     // the data of a Set of Configuration 10
  std::optional<std::uint8_t> last_input_byte;  // DIN of the last poll response
};

class StartupTolerance : public ::testing::TestWithParam<Reading> {
 protected:
  void build(const Reading& reading) {
    auto config = rack_config({kMac});
    config.create_devices = false;
    // The node asks 250 ms; a coarse device keeps 300.
    config.pumps[0].node.expected_packet_rate = milliseconds(250);
    if (pump_adjust_) pump_adjust_(config.pumps[0]);
    expected_io_ = config.pumps[0].io;
    // After the profile is made: a reading may change the paths it asks.
    config.adjust_scan_list = [node = reading.node](devicenet::ScannerConfig& port) {
      if (node) node(port.nodes.at(0));
    };
    rack_ = std::make_unique<sim::SimRack>(std::move(config));
    rack_->observe(events_);
    sim::SlaveOptions options = sim::default_slave_options(mac(kMac));
    // A device fresh from the factory: the CDN118 preset in its E2, so that
    // the master has the configuration to write.
    options.configuration = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);
    reading.device(options);
    rack_->world().bus().set_tap([this](const sim::WireFrame& f) { count(f); });
    rack_->add_device(std::move(options), std::nullopt);
    rack_->start();
  }

  void count(const sim::WireFrame& f) {
    const auto& d = f.frame.data;
    const std::size_t len = f.frame.len;
    if (f.frame.id == devicenet::group2_id(mac(kMac),
                                           devicenet::Group2Message::kUnconnectedExplicitRequest) &&
        len == 6 && d[1] == 0x4B) {
      if (d[4] == 0x01) ++wire_.allocate_explicit;
      if (d[4] == 0x02) ++wire_.allocate_poll;
      if (d[4] != 0x01 && d[4] != 0x02) ADD_FAILURE() << "Allocate with choice " << int{d[4]};
    }
    if (f.frame.id ==
        devicenet::group2_id(mac(kMac), devicenet::Group2Message::kMasterExplicitRequest)) {
      // Unfragmented [hdr][10][class][inst][attr]..., or a first fragment
      // [hdr|frag][00][10][class][inst][attr]...
      const bool frag = (d[0] & 0x80) != 0;
      const std::size_t at = frag ? 2 : 1;
      if (frag && (len < 2 || d[1] != 0x00)) return;
      if (len >= at + 4 && d[at] == 0x10) {
        if (d[at + 1] == 0x05 && d[at + 2] == 0x02 && (d[at + 3] == 14 || d[at + 3] == 16)) {
          ++wire_.path_sets;
        }
        if (d[at + 1] == 0x40) ++wire_.configuration_sets;
        if (d[at + 1] == 0x40 && d[at + 3] == 10) {
          wire_.no_nc_mask_set.assign(d.begin() + static_cast<std::ptrdiff_t>(at + 4),
                                      d.begin() + static_cast<std::ptrdiff_t>(len));
        }
      }
    }
    // The CDN127 preset's response: [DSUP][DIN][AIN1][AIN1][AIN2][AIN2].
    if (f.frame.id ==
            devicenet::group1_id(devicenet::Group1Message::kSlavePollResponse, mac(kMac)) &&
        len == 6) {
      wire_.last_input_byte = d[1];
    }
  }

  const rack::PumpView& view() { return *rack_->pumps().pump(mac(kMac)); }
  const devicenet::Node& node() { return *rack_->scanner().node(mac(kMac)); }
  sim::Cdn127Slave& device() { return rack_->device(mac(kMac)).device(); }

  // Online, 100 polls and more without a reconnection, a command applied.
  void expect_online_and_serving() {
    ASSERT_TRUE(
        rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)))
        << view().reason;
    EXPECT_EQ(wire_.allocate_explicit, 1u);
    EXPECT_EQ(wire_.allocate_poll, 1u);
    const auto polls = node().counters().polls;
    ASSERT_TRUE(rack_->world().run_until([&] { return node().counters().polls >= polls + 100; },
                                         seconds(30)));
    EXPECT_EQ(view().state, NodeState::kOnline) << view().reason;
    EXPECT_EQ(node().counters().reconnects, 0u);
    EXPECT_EQ(node().counters().timeouts, 0u) << "poll timeouts";
    EXPECT_EQ(node().explicit_counters().timeouts, 0u) << "explicit timeouts";

    cdn127::PumpOutputs out;
    out.pump_on = true;
    out.analog_out_raw = 1234;
    ASSERT_TRUE(rack_->pumps().command(mac(kMac), out, rack_->now()).ok());
    ASSERT_TRUE(rack_->world().run_until([&] { return device().outputs() == out; }, seconds(2)));
    rack_->world().run_for(milliseconds(500));
    EXPECT_EQ(view().outputs_applied, out);
    EXPECT_FALSE(view().outputs_idle);
    EXPECT_EQ(wire_.allocate_explicit, 1u);
    EXPECT_EQ(wire_.allocate_poll, 1u);
    // The configuration the node asked for, in the device.
    EXPECT_EQ(device().device().configuration(), expected_io_);
  }

  std::unique_ptr<sim::SimRack> rack_;
  EventRecorder events_;
  Wire wire_;
  std::function<void(rack::PumpConfig&)> pump_adjust_;
  cdn127::IoConfiguration expected_io_;
};

void locked(sim::SlaveOptions& o) { o.configuration_locked_while_poll_allocated = true; }
void fixed_paths(sim::SlaveOptions& o) { o.poll_paths_fixed = true; }
void idle_empty(sim::SlaveOptions& o) { o.idle_poll_answered_empty = true; }
void no_last_ack(sim::SlaveOptions& o) { o.no_ack_of_last_request_fragment = true; }
void slow_explicit(sim::SlaveOptions& o) { o.explicit_response_delay = milliseconds(300); }
void slow_poll(sim::SlaveOptions& o) { o.poll_response_delay = milliseconds(3); }
void serial_uint(sim::SlaveOptions& o) { o.serial_number_udint = false; }
void serial_udint(sim::SlaveOptions& o) { o.serial_number_udint = true; }
void no_identity_state(sim::SlaveOptions& o) { o.unsupported_attributes.push_back({0x01, 8}); }
void coarse_epr(sim::SlaveOptions& o) { o.timer_resolution = milliseconds(100); }
void paths_16bit(devicenet::NodeConfig& n) {
  n.profile.produced_path = kProducedPath16;
  n.profile.consumed_path = kConsumedPath16;
}

TEST_P(StartupTolerance, ComesOnlineAndServes) {
  build(GetParam());
  expect_online_and_serving();
}

INSTANTIATE_TEST_SUITE_P(
    Readings, StartupTolerance,
    ::testing::Values(Reading{"AsThisSimulatorReadsTheManual", [](sim::SlaveOptions&) {}},
                      Reading{"ConfigurationLockedWhilePollAllocated", locked},
                      Reading{"PollPathsFixed", fixed_paths},
                      Reading{"PollPathsFixedAndSpelledOtherwise", fixed_paths, paths_16bit},
                      Reading{"IdlePollsAnsweredEmpty", idle_empty},
                      Reading{"NoAckOfTheLastRequestFragment", no_last_ack, paths_16bit},
                      Reading{"SlowExplicitAnswers", slow_explicit},
                      Reading{"SlowPollAnswers", slow_poll},
                      Reading{"SerialNumberUint", serial_uint},
                      Reading{"SerialNumberUdint", serial_udint},
                      Reading{"NoIdentityState", no_identity_state},
                      Reading{"ExpectedPacketRateInStepsOf100ms", coarse_epr},
                      Reading{"EveryReadingTogether", sim::apply_field_reading, paths_16bit}),
    [](const ::testing::TestParamInfo<Reading>& param) { return param.param.name; });

// ---------------------------------------------------------------------------
// What each reading asks of the master, beyond coming online.

class StartupReading : public StartupTolerance {};

// Configure before polling: the configuration is written while no poll
// connection exists, and read back; the poll connection comes after.
TEST_F(StartupReading, ConfigurationIsWrittenBeforeThePollConnectionExists) {
  build({"locked", locked});
  expect_online_and_serving();
  // Mode, counts (DI, DO, AI, AO): what differs between the CDN118 and CDN127
  // presets; NoNcMask (0 in both) not written.
  const cdn127::IoConfiguration a = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);
  const cdn127::IoConfiguration b = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  unsigned differ = 0;
  for (bool d :
       {a.mode != b.mode, a.num_digital_inputs != b.num_digital_inputs,
        a.num_digital_outputs != b.num_digital_outputs, a.num_analog_inputs != b.num_analog_inputs,
        a.num_analog_outputs != b.num_analog_outputs, a.no_nc_mask != b.no_nc_mask}) {
    differ += d ? 1 : 0;
  }
  EXPECT_EQ(wire_.configuration_sets, differ);
  // And the analog output's fault and idle states: this simulator's factory
  // "hold the last value" differs from the configured 0 V.
  EXPECT_EQ(node().counters().settings_written, differ + 2);
  EXPECT_EQ(device().counters().requests_refused, 0u);
}

// A device that already matches: the start-up writes nothing.
TEST_F(StartupReading, ADeviceThatMatchesIsWrittenNothing) {
  // The safe state this simulator leaves the factory with: outputs off,
  // the analog output holding its value.
  pump_adjust_ = [](rack::PumpConfig& p) {
    p.safe_state.values.analog_fault = {cdn127::AnalogAction::Kind::kHold, 0};
    p.safe_state.values.analog_idle = {cdn127::AnalogAction::Kind::kHold, 0};
  };
  build({"matching", [](sim::SlaveOptions& o) {
           o.configuration = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
           o.poll_paths_fixed = true;
         }});
  expect_online_and_serving();
  EXPECT_EQ(wire_.configuration_sets, 0u);
  EXPECT_EQ(wire_.path_sets, 0u);
  EXPECT_EQ(node().counters().settings_written, 0u);
  EXPECT_EQ(device().counters().requests_refused, 0u);
}

// Fixed paths that differ in form only: the Set is refused, the sizes of the
// paths in force are the configuration's, the node goes on.
TEST_F(StartupReading, RefusedPathsThatServeAreKept) {
  build({"fixed", fixed_paths, paths_16bit});
  expect_online_and_serving();
  EXPECT_EQ(wire_.path_sets, 2u);
  EXPECT_EQ(device().counters().requests_refused, 2u);  // the two Sets, 0x0E
}

// Fixed paths that cannot serve: a configuration fault naming the path the
// device has and the one that was needed.
TEST_F(StartupReading, RefusedPathsThatDoNotServeAreAConfigurationFault) {
  build({"fixed", fixed_paths, [](devicenet::NodeConfig& n) {
           // Produced assembly 1, the exception alarms byte alone.
           n.profile.produced_path = {0x20, 0x04, 0x24, 0x01, 0x30, 0x03};
           n.profile.produced_size = 1;
         }});
  ASSERT_TRUE(rack_->world().run_until(
      [&] { return view().state == NodeState::kConfigurationFault; }, seconds(20)));
  const std::string& r = view().reason;
  EXPECT_NE(r.find("device refused Set Connection 2 (poll).ProducedConnectionPath = 20 04 24 01 "
                   "30 03 (attribute not settable (0x0E/0xFF)); it has 20 04 24 67 30 03"),
            std::string::npos)
      << r;
  EXPECT_NE(r.find("poll sizes differ"), std::string::npos) << r;
  EXPECT_EQ(node().counters().polls, 0u);
  // Re-checked every 10 s, with the same outcome: the reason stays as it is
  // (no refusal of an earlier attempt added), and it is no news.
  const std::string first = r;
  const std::size_t events = events_.of(mac(kMac)).size();
  rack_->world().run_for(seconds(35));
  EXPECT_GE(node().counters().allocate_attempts, 4u);
  EXPECT_EQ(view().reason, first);
  EXPECT_EQ(events_.of(mac(kMac)).size(), events);
}

// An idle node whose device answers idle polls empty: 100 idle polls, no
// error, the connection alive; the inputs keep the time of the last
// response that carried them.
TEST_F(StartupReading, EmptyAnswersToIdlePollsKeepTheConnection) {
  build({"idle empty", idle_empty});
  ASSERT_TRUE(
      rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)));
  const auto before = node().counters();
  rack_->world().run_for(seconds(11));  // 110 polls at 100 ms
  const auto& after = node().counters();
  EXPECT_GE(after.idle_polls - before.idle_polls, 100u);
  // Every idle poll answered empty (one may be in flight at either end).
  EXPECT_NEAR(static_cast<double>(after.idle_empty_responses - before.idle_empty_responses),
              static_cast<double>(after.idle_polls - before.idle_polls), 1.0);
  EXPECT_EQ(after.errors, before.errors);
  EXPECT_EQ(after.reconnects, 0u);
  EXPECT_EQ(view().state, NodeState::kOnline);
  EXPECT_TRUE(view().outputs_idle);
  EXPECT_FALSE(view().has_inputs) << "an empty answer carries no inputs";

  // Commanded, the device answers with data: inputs. Idle again: what they
  // last were is not published as what they are.
  cdn127::PumpOutputs out;
  out.pump_on = true;
  ASSERT_TRUE(rack_->pumps().command(mac(kMac), out, rack_->now()).ok());
  ASSERT_TRUE(rack_->world().run_until([&] { return view().has_inputs; }, seconds(1)));
  EXPECT_FALSE(view().inputs_withheld_when_idle);
  ASSERT_TRUE(rack_->pumps().release_command(mac(kMac), rack_->now()).ok());
  ASSERT_TRUE(rack_->world().run_until([&] { return view().outputs_idle; }, seconds(1)));
  EXPECT_FALSE(view().has_inputs);
  EXPECT_TRUE(view().inputs_withheld_when_idle);
}

// The response to a fragmented request without the ack of its last fragment
// ends the transaction, and is counted.
TEST_F(StartupReading, AResponseWithoutTheLastAckIsTaken) {
  build({"no last ack", no_last_ack, paths_16bit});
  expect_online_and_serving();
  EXPECT_EQ(wire_.path_sets, 2u);  // the two 15-byte Sets, in fragments
  EXPECT_EQ(node().explicit_counters().responses_before_final_ack, 2u);
}

// No Identity.State: state unknown, said in the reason; the keep-alive
// reads Identity.Status instead, with no refusal.
TEST_F(StartupReading, NoIdentityStateIsStateUnknown) {
  build({"no state", no_identity_state});
  ASSERT_TRUE(
      rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)));
  EXPECT_NE(view().reason.find("Identity.State not supported: state unknown"), std::string::npos)
      << view().reason;
  EXPECT_FALSE(node().identity().state.has_value());
  EXPECT_TRUE(node().identity().status.has_value());
  const auto refused = device().counters().requests_refused;
  rack_->world().run_for(seconds(10));  // four keep-alives at the 2500 ms explicit EPR
  EXPECT_EQ(device().counters().requests_refused, refused);
  EXPECT_EQ(view().state, NodeState::kOnline);
}

// The rate the device keeps is the one used and shown.
TEST_F(StartupReading, TheDevicesExpectedPacketRateIsUsed) {
  build({"coarse", coarse_epr});
  ASSERT_TRUE(
      rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)));
  EXPECT_EQ(node().poll_epr(), milliseconds(300));  // 250 asked, rounded up
  EXPECT_NE(view().reason.find("EPR 300 ms"), std::string::npos) << view().reason;
}

// NoNcMask (Configuration attribute 10; CDN127 manual: "If the bit is clear
// the input is reported as a '1' when the input is active. If the NoNcMask
// bit is set the input is reported as a '0' when the input is active"). The
// reading taken (bridge/profiles/cdn127/io_data.cpp): the mask changes how
// the device reports its five pump inputs, nothing else; the master writes
// the configured mask like any Configuration attribute and decodes with it,
// so that what is published means the same whatever the wiring. On the wire:
// the Set of attribute 10, and input bytes the device inverts where the mask
// says.
TEST_F(StartupReading, NoNcMaskIsWrittenAndTheInputsDecodedWithIt) {
  constexpr std::uint8_t kMask = 0x1C;  // N2 flow, alarm, interlock: normally closed
  pump_adjust_ = [](rack::PumpConfig& p) { p.io.no_nc_mask = kMask; };
  build({"mask", [](sim::SlaveOptions&) {}});
  expect_online_and_serving();
  EXPECT_EQ(wire_.no_nc_mask_set, std::vector<std::uint8_t>{kMask});
  EXPECT_EQ(device().device().configuration().no_nc_mask, kMask);

  const cdn127::PumpInputs truth = device().device().pump().inputs();
  ASSERT_TRUE(wire_.last_input_byte);
  EXPECT_EQ(*wire_.last_input_byte, truth.encode(kMask)) << "the device applies the mask";
  EXPECT_NE(*wire_.last_input_byte, truth.encode(0));
  ASSERT_TRUE(view().has_inputs);
  ASSERT_TRUE(view().inputs.pump.has_value());
  EXPECT_EQ(*view().inputs.pump, truth) << "decoded with the mask: the meaning, not the wiring";
}

// Serial numbers in either width reach the identity.
TEST_F(StartupReading, SerialNumberInTwoOrFourBytes) {
  build({"uint", [](sim::SlaveOptions& o) {
           o.serial_number = 0x00ABCDEF;
           o.serial_number_udint = false;
         }});
  ASSERT_TRUE(
      rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)));
  EXPECT_EQ(node().identity().serial_number, 0xCDEFu);  // the UINT's 16 bits

  wire_ = {};
  build({"udint", [](sim::SlaveOptions& o) {
           o.serial_number = 0x00ABCDEF;
           o.serial_number_udint = true;
         }});
  ASSERT_TRUE(
      rack_->world().run_until([&] { return view().state == NodeState::kOnline; }, seconds(20)));
  EXPECT_EQ(node().identity().serial_number, 0x00ABCDEFu);
}

}  // namespace
}  // namespace dnbridge::test
