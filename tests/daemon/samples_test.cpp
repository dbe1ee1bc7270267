// What the bridge publishes for a node whose analog input is off the scale:
// the channel marked invalid in PumpState (raw as received, volts NaN), the
// other inputs as decoded, and NodeStatus saying which input and counting;
// and strings, UTF-8 whatever the device sends.
#include "adapters/daemon/samples.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/profile_topics.hpp"
#include "adapters/dds/topics.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/rack/rack_port.hpp"
#include "support/example_eds.hpp"

namespace dnbridge::daemon {
namespace {

namespace cdn127 = profiles::cdn127;

class NullSink final : public can::FrameSink {
 public:
  void send(const can::CanFrame&, TimePoint) override {}
};

TEST(Samples, AnAnalogInputOffTheScaleIsInvalidAndNamed) {
  rack::PumpConfig pump;
  pump.node.mac = devicenet::MacId::from(6).value();
  pump.node.name = "pump-6";
  pump.io = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  rack::PumpRack rack({pump});
  NullSink sink;
  devicenet::Scanner scanner(rack::PumpRack::scanner_config({}, {pump}), sink, rack, Logger());

  rack.on_node_state(pump.node.mac, devicenet::NodeState::kVerifying, devicenet::NodeState::kOnline,
                     "online", TimePoint{} + seconds(1));
  // [DSUP 00][inputs 1F: all normal][AIN1 1234 = D2 04][AIN2 65535 = FF FF]
  const std::uint8_t response[] = {0x00, 0x1F, 0xD2, 0x04, 0xFF, 0xFF};
  rack.on_poll_response(pump.node.mac, Bytes(response), TimePoint{} + seconds(1));
  const rack::PumpView& view = *rack.pump(pump.node.mac);

  dds::Owned<dnbridge_PumpState> state;
  fill_pump_state(*state, "r", "A", view);
  EXPECT_TRUE(state->inputs_valid);
  EXPECT_TRUE(state->interlock_ok);
  EXPECT_EQ(state->analog_input_count, 2);
  EXPECT_TRUE(state->analog_input_valid[0]);
  EXPECT_NEAR(state->analog_input_volts[0], 1234 * 10.0 / 4095, 1e-3);
  EXPECT_FALSE(state->analog_input_valid[1]);
  EXPECT_EQ(state->analog_input_raw[1], 65535);
  EXPECT_TRUE(std::isnan(state->analog_input_volts[1]));

  dds::Owned<dnbridge_NodeStatus> status;
  fill_node_status(*status, "r", "A", view, port::NodeStatusView::of(*scanner.node(pump.node.mac)));
  EXPECT_STREQ(status->invalid_inputs, "analog input 2: 65535 counts, above 4095");
  EXPECT_EQ(status->counters.responses_with_invalid_inputs, 1u);

  // In range again: nothing invalid, the count stays.
  const std::uint8_t good[] = {0x00, 0x1F, 0xD2, 0x04, 0x00, 0x08};
  rack.on_poll_response(pump.node.mac, Bytes(good), TimePoint{} + seconds(2));
  fill_pump_state(*state, "r", "A", view);
  EXPECT_TRUE(state->analog_input_valid[1]);
  fill_node_status(*status, "r", "A", view, port::NodeStatusView::of(*scanner.node(pump.node.mac)));
  EXPECT_STREQ(status->invalid_inputs, "");
  EXPECT_EQ(status->counters.responses_with_invalid_inputs, 1u);
}

TEST(Samples, ADevicesProductNameIsPublishedAsUtf8) {
  rack::PumpConfig pump;
  pump.node.mac = devicenet::MacId::from(7).value();
  pump.node.name = "Pumpe \xC3\xA4tz";  // UTF-8 from the configuration, as it is
  pump.io = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  rack::PumpRack rack({pump});
  NullSink sink;
  devicenet::Scanner scanner(rack::PumpRack::scanner_config({}, {pump}), sink, rack, Logger());
  const rack::PumpView* view = rack.pump(pump.node.mac);
  ASSERT_NE(view, nullptr);

  auto node = port::NodeStatusView::of(*scanner.node(pump.node.mac));
  node.identity.product_name = "\xB5Pump \xE4";  // ISO 8859-1, as the device sends it
  dds::Owned<dnbridge_NodeStatus> status;
  fill_node_status(*status, "r", "A", *view, node);
  EXPECT_STREQ(status->product_name, "\xC2\xB5Pump \xC3\xA4");
  EXPECT_STREQ(status->name, "Pumpe \xC3\xA4tz");
}

// A device's NodeStatus says where its safe state comes from: the
// configuration's parameters, or the device's own (safe_state = "device").
TEST(Samples, ADevicesSafeStateSourceIsPublished) {
  rack::DeviceConfig d;
  d.node.mac = devicenet::MacId::from(20).value();
  d.node.name = "io-20";
  d.eds = std::make_shared<const profiles::eds::EdsFile>(test::example_eds(test::kIoBlockEds));
  d.settings.safe_state_of_device = true;
  rack::DeviceRack rack({d});
  NullSink sink;
  devicenet::Scanner scanner(rack::DeviceRack::scanner_config({}, {d}), sink, rack, Logger());
  const rack::DeviceView* view = rack.device(d.node.mac);
  ASSERT_NE(view, nullptr);
  dds::Owned<dnbridge_NodeStatus> status;
  fill_node_status(*status, "r", "A", *view, port::NodeStatusView::of(*scanner.node(d.node.mac)));
  EXPECT_EQ(status->safe_state_source, dnbridge_SAFE_STATE_DEVICE);
  EXPECT_FALSE(status->safe_state_known);  // not read yet: the node is not online
  d.settings.safe_state_of_device = false;
  d.settings.safe_state = {{"Output idle action", 0}};
  rack::DeviceRack configured({d});
  fill_node_status(*status, "r", "A", *configured.device(d.node.mac),
                   port::NodeStatusView::of(*scanner.node(d.node.mac)));
  EXPECT_EQ(status->safe_state_source, dnbridge_SAFE_STATE_CONFIGURED);
}

// Every profile a port of the rack file has is registered with its DDS
// topics, once: a profile left out would have nodes that are neither
// published nor commanded.
TEST(ProfileTopics, EveryProfileOfARackPortHasItsTopicsOnce) {
  NullSink sink;
  rack::RackPort port({}, to_port_nodes(PortConfig{}), sink, Logger());
  const auto registered = bridge_profiles();
  ASSERT_EQ(registered.size(), port.profiles().size());
  for (const rack::ProfileNodes* nodes : port.profiles()) {
    SCOPED_TRACE(std::string(nodes->profile()));
    EXPECT_EQ(std::count_if(registered.begin(), registered.end(),
                            [&](const ProfileTopics& t) { return t.profile == nodes->profile(); }),
              1);
  }
  // The CDN127's are required (the bridge does not run without them); the
  // topics are the IDL's.
  EXPECT_EQ(registered[0].profile, rack::PumpProfile::kName);
  EXPECT_TRUE(registered[0].required);
  EXPECT_EQ(registered[0].state_topic, dds::TopicTraits<dnbridge_PumpState>::kName);
  EXPECT_EQ(registered[0].command_topic, dds::TopicTraits<dnbridge_PumpCommand>::kName);
  EXPECT_EQ(registered[1].profile, rack::DeviceProfile::kName);
  EXPECT_FALSE(registered[1].required);
  EXPECT_EQ(registered[1].state_topic, dds::TopicTraits<dnbridge_DeviceState>::kName);
  EXPECT_EQ(registered[1].command_topic, dds::TopicTraits<dnbridge_DeviceCommand>::kName);
}

}  // namespace
}  // namespace dnbridge::daemon
