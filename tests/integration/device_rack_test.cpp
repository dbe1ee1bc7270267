// Devices described by their EDS files (profile "eds") in a rack, against
// the simulated device driven by the same EDS: the start-up downloads the
// parameters and the safe state, inputs are read as the EDS's fields,
// commands by field or by bytes are checked before the master gets them,
// and the safe state is what the outputs do when the commander or the
// node goes. A reload moves a node between the pump and device racks.
#include "bridge/rack/device_rack.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "rack_fixture.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::test {
namespace {

using ::testing::HasSubstr;
using ByteVec = std::vector<std::uint8_t>;

constexpr unsigned kIo = 20;

// The example I/O block at MAC 20: Input filter 5 ms; outputs 0x80 on
// idle, 0x01 on a fault.
rack::DeviceConfig io_block(unsigned mac_value = kIo) {
  rack::DeviceConfig d;
  d.node.mac = mac(mac_value);
  d.node.name = "io " + std::to_string(mac_value);
  d.node.poll_period = milliseconds(50);
  d.node.expected_packet_rate = milliseconds(250);
  d.eds = std::make_shared<const profiles::eds::EdsFile>(example_eds(kIoBlockEds));
  d.eds_path = kIoBlockEds;
  d.settings.parameters = {{"Input filter", 5}};
  d.settings.safe_state = {{"Output fault action", 0},
                           {"Output fault value", 0x01},
                           {"Output idle action", 0},
                           {"Output idle value", 0x80}};
  return d;
}

class DeviceRackTest : public ::testing::Test {
 protected:
  void start(std::vector<rack::DeviceConfig> devices = {io_block()},
             std::vector<unsigned> pumps = {}) {
    auto config = rack_config(pumps);
    config.devices = std::move(devices);
    rack_.emplace(config);
    rack_->start();
  }
  bool run_until_online() {
    return world().run_until([&] { return rack_->all_online(); }, seconds(20));
  }
  sim::SimWorld& world() { return rack_->world(); }
  rack::DeviceRack& devices() { return rack_->devices(); }
  const rack::DeviceView& view(unsigned m = kIo) { return *devices().device(mac(m)); }
  sim::EdsSlave& device(unsigned m = kIo) { return rack_->eds_device(mac(m)).device(); }
  double param(unsigned n, unsigned m = kIo) { return *device(m).objects().param_number(n); }
  TimePoint now() { return rack_->now(); }

  std::optional<sim::SimRack> rack_;
};

TEST_F(DeviceRackTest, TheStartUpDownloadsParametersAndSafeStateAndReadsTheInputsAsFields) {
  start();
  ASSERT_TRUE(run_until_online()) << view().reason;
  // Downloaded to the device, and read back.
  EXPECT_EQ(param(1), 5);
  EXPECT_EQ(param(7), 0x01);
  EXPECT_EQ(param(9), 0x80);
  EXPECT_EQ(view().safe_state_text,
            "Param6 Output fault action = 0; Param7 Output fault value = 1; Param8 Output idle "
            "action = 0; Param9 Output idle value = 128");
  EXPECT_EQ(view().product, "Example IO block 8DI/8DO/1AI");

  // Inputs change on the device: DI 0xA5, analog input -1000 mV.
  ASSERT_TRUE(device().objects().set_param_value(3, Bytes(ByteVec{0xA5})));
  ASSERT_TRUE(device().objects().set_param_value(2, Bytes(ByteVec{0x18, 0xFC})));
  world().run_for(milliseconds(120));
  ASSERT_TRUE(view().has_inputs);
  EXPECT_EQ(view().inputs, (ByteVec{0xA5, 0x00, 0x18, 0xFC}));
  ASSERT_EQ(view().input_values.size(), 3u);
  const auto& layout = view().io->produced;
  EXPECT_EQ(layout.fields[view().input_values[0].field].name, "Digital inputs");
  EXPECT_EQ(view().input_values[0].value, 0xA5);
  EXPECT_EQ(layout.fields[view().input_values[2].field].name, "Analog input 1");
  EXPECT_EQ(view().input_values[2].value, -1000);
}

// safe_state = "device": the device's maker fixes its outputs' fault and
// idle behaviour; the master reads what the EDS names for it, shows it and
// writes none of it.
TEST_F(DeviceRackTest, ADeviceWithItsOwnSafeStateIsReadAndShownNeverWritten) {
  rack::DeviceConfig d = io_block();
  d.settings.safe_state.clear();
  d.settings.safe_state_of_device = true;
  start({d});
  ASSERT_TRUE(device().objects().set_param_value(7, Bytes(ByteVec{0x3C})));
  ASSERT_TRUE(device().objects().set_param_value(9, Bytes(ByteVec{0x0F})));
  ASSERT_TRUE(run_until_online()) << view().reason;
  EXPECT_EQ(param(1), 5);  // the node's parameters are still downloaded
  EXPECT_EQ(param(7), 0x3C);
  EXPECT_EQ(param(9), 0x0F);
  EXPECT_TRUE(view().safe_state_of_device);
  EXPECT_TRUE(view().safe_state_read);
  EXPECT_EQ(view().safe_state_text,
            "the device's own (safe_state = \"device\"): Param6 Output fault action = 0; Param7 "
            "Output fault value = 60; Param8 Output idle action = 0; Param9 Output idle value = "
            "15");
}

TEST_F(DeviceRackTest, ACommandByFieldsOrBytesReachesTheOutputsAfterItsChecks) {
  start();
  ASSERT_TRUE(run_until_online()) << view().reason;
  ASSERT_TRUE(devices()
                  .command(mac(kIo),
                           std::vector<profiles::eds::FieldSetting>{{"Digital outputs", 0x81}},
                           "supervisor-a", now())
                  .ok())
      << view().last_command_refused;
  world().run_for(milliseconds(120));
  EXPECT_EQ(param(4), 0x81);
  EXPECT_FALSE(view().outputs_idle);
  EXPECT_EQ(view().outputs_applied, (ByteVec{0x81, 0x00}));
  EXPECT_EQ(view().commanded_by, "supervisor-a");

  ASSERT_TRUE(devices().command(mac(kIo), ByteVec{0x03, 0x00}, "supervisor-b", now()).ok());
  world().run_for(milliseconds(120));
  EXPECT_EQ(param(4), 0x03);

  // Refused, each with its reason, and nothing of them applied.
  struct Bad {
    Status status;
    const char* says;
  };
  const Bad refused[] = {
      {devices().command(mac(kIo),
                         std::vector<profiles::eds::FieldSetting>{{"Digital outputs", 256}}, "x",
                         now()),
       "from x: Digital outputs: 256 is outside 0..255"},
      {devices().command(mac(kIo), std::vector<profiles::eds::FieldSetting>{{"Digital output", 1}},
                         "x", now()),
       "from x: no field \"Digital output\""},
      {devices().command(mac(kIo), ByteVec{0x03}, "x", now()),
       "from x: 1 bytes given, \"Outputs\" is 2 bytes"},
      {devices().command(mac(kIo), ByteVec{0x03, 0x01}, "x", now()),
       "from x: bit 0 of byte 1 is set, and the EDS gives it no field"},
  };
  for (const auto& r : refused) {
    EXPECT_FALSE(r.status.ok()) << r.says;
  }
  EXPECT_EQ(view().commands_refused, 4u);
  EXPECT_THAT(view().last_command_refused, HasSubstr(refused[3].says));
  world().run_for(milliseconds(120));
  EXPECT_EQ(param(4), 0x03);
  EXPECT_EQ(view().commanded_by, "supervisor-b");
  EXPECT_EQ(devices().command(mac(41), ByteVec{0, 0}, "x", now()).error(),
            make_error_code(Errc::kOutOfRange));
}

TEST_F(DeviceRackTest, ANodeNotOnlineIsNotCommanded) {
  start();
  // Before its start-up is done.
  EXPECT_EQ(devices().command(mac(kIo), ByteVec{0x01, 0x00}, "early", now()).error(),
            make_error_code(Errc::kNotConnected));
  EXPECT_THAT(view().last_command_refused, HasSubstr("from early: the node is not online"));
  ASSERT_TRUE(run_until_online());
  world().run_for(milliseconds(120));
  EXPECT_EQ(param(4), 0x80);  // idle: the configured idle value
  EXPECT_TRUE(view().outputs_idle);
}

TEST_F(DeviceRackTest, TheDeviceTakesItsConfiguredIdleStateWhenTheLastCommanderGoes) {
  start();
  ASSERT_TRUE(run_until_online());
  ASSERT_TRUE(devices().command(mac(kIo), ByteVec{0x0F, 0x00}, "s", now()).ok());
  world().run_for(milliseconds(120));
  ASSERT_EQ(param(4), 0x0F);
  ASSERT_TRUE(devices().release_command(mac(kIo), now()).ok());
  world().run_for(milliseconds(120));
  EXPECT_EQ(param(4), 0x80);
  EXPECT_TRUE(view().outputs_idle);
  EXPECT_EQ(view().idle_reason(), "idle: no live commander");
}

TEST_F(DeviceRackTest, AfterALossTheOutputsTakeTheFaultValueAndComeBackIdle) {
  start();
  ASSERT_TRUE(run_until_online());
  ASSERT_TRUE(devices().command(mac(kIo), ByteVec{0x0F, 0x00}, "s", now()).ok());
  world().run_for(milliseconds(120));
  // The cable is cut: the device's poll connection times out (its fault
  // value), the master loses the node.
  rack_->eds_device(mac(kIo)).disconnect();
  ASSERT_TRUE(world().run_until([&] { return !view().online; }, seconds(5)));
  world().run_for(seconds(2));
  EXPECT_EQ(param(4), 0x01);
  rack_->eds_device(mac(kIo)).reconnect();
  ASSERT_TRUE(run_until_online());
  world().run_for(milliseconds(120));
  // Back idle: the command before the loss is void.
  EXPECT_TRUE(view().outputs_idle);
  EXPECT_FALSE(view().outputs_requested.has_value());
  EXPECT_EQ(view().idle_reason(), "idle: waiting for a new command after reconnection");
  EXPECT_EQ(param(4), 0x80);
}

TEST_F(DeviceRackTest, ADeviceWhoseMemberListDiffersFromTheEdsIsAConfigurationFault) {
  // The device's own EDS has the input assembly's first two members swapped.
  profiles::eds::EdsFile differing = example_eds(kIoBlockEds);
  for (auto& a : differing.assemblies) {
    if (a.number == 100) std::swap(a.members[0], a.members[1]);
  }
  auto config = rack_config({});
  config.devices = {io_block()};
  config.create_devices = false;
  rack_.emplace(config);
  rack_->add_eds_device(differing, sim::default_eds_slave_options(mac(kIo)), std::nullopt);
  rack_->start();
  ASSERT_TRUE(world().run_until([&] { return view().state == NodeState::kConfigurationFault; },
                                seconds(10)))
      << view().reason;
  EXPECT_EQ(view().reason,
            "Assembly 100 member list (Assem100 Inputs and status) differs from what the "
            "configuration expects: member 1: class 0x0F instance 0x05 attribute 0x01 on the "
            "device, Param3 (Digital inputs), class 0x0F instance 0x03 attribute 0x01 in the EDS; "
            "member 2: class 0x0F instance 0x03 attribute 0x01 on the device, Param5 (Module "
            "status), class 0x0F instance 0x05 attribute 0x01 in the EDS");
  EXPECT_FALSE(view().online);
}

TEST_F(DeviceRackTest, ADeviceWithoutMemberListsIsNotComparedAndComesOnline) {
  // A device that describes its assemblies only in its EDS: Assembly
  // attributes 1 and 2 answer 0x14. Nothing to compare: online, its inputs
  // read as the EDS lays them out.
  auto config = rack_config({});
  config.devices = {io_block()};
  config.create_devices = false;
  rack_.emplace(config);
  auto options = sim::default_eds_slave_options(mac(kIo));
  options.member_lists = false;
  rack_->add_eds_device(example_eds(kIoBlockEds), options, std::nullopt);
  rack_->start();
  ASSERT_TRUE(run_until_online()) << view().reason;
  ASSERT_TRUE(device().objects().set_param_value(3, Bytes(ByteVec{0x3C})));
  world().run_for(milliseconds(120));
  ASSERT_TRUE(view().has_inputs);
  EXPECT_EQ(view().input_values[0].value, 0x3C);
}

TEST_F(DeviceRackTest, APumpAndADeviceShareAPortAndAReloadMovesANodeBetweenThem) {
  start({io_block()}, {1});
  ASSERT_TRUE(run_until_online());
  EXPECT_TRUE(rack_->pumps().pump(mac(1))->online);

  // MAC 1 becomes a device of profile "eds", MAC 20 goes: no CDN127 answers
  // at 1 as the EDS expects, so it is a wrong device there.
  auto port = rack_->scanner().config();
  rack::PortNodes next;
  next.of<rack::DeviceConfig>() = {io_block(1)};
  const auto change = rack_->port().reconfigure(port, next, now());
  EXPECT_EQ(change.reconfigured, (std::vector<devicenet::MacId>{mac(1)}));
  EXPECT_EQ(change.removed, (std::vector<devicenet::MacId>{mac(kIo)}));
  EXPECT_EQ(rack_->pumps().pump(mac(1)), nullptr);
  ASSERT_NE(devices().device(mac(1)), nullptr);
  EXPECT_EQ(devices().device(mac(kIo)), nullptr);
  ASSERT_TRUE(world().run_until(
      [&] { return devices().device(mac(1))->state == NodeState::kWrongDevice; }, seconds(10)));
  EXPECT_THAT(devices().device(mac(1))->reason, HasSubstr("65001"));
}

}  // namespace
}  // namespace dnbridge::test
