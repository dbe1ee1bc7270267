// A device described by its EDS file (profile "eds") end to end: the bridge
// publishes its DeviceState (bytes and the EDS's fields) and NodeStatus
// (its safe state read back), a DeviceCommand by fields or by bytes reaches
// the simulated device, a refused one says why, the commander's departure
// leaves the device in its configured idle state, and each command topic
// commands only the nodes of its kind.
#include <memory>

#include "bridge_fixture.hpp"

namespace dnbridge::e2e {
namespace {

constexpr unsigned kDevice = 20;

// A supervisor process that commands devices: their bytes, their fields,
// or both (a malformed command).
class Supervisor : public TestCommander<dnbridge_DeviceCommand> {
 public:
  using TestCommander::TestCommander;
  bool write_fields(unsigned mac, const std::vector<std::pair<std::string, double>>& fields) {
    return write_both(mac, {}, fields);
  }
  bool write_bytes(unsigned mac, const std::vector<std::uint8_t>& outputs) {
    return write_both(mac, outputs, {});
  }
  bool write_both(unsigned mac, const std::vector<std::uint8_t>& outputs,
                  const std::vector<std::pair<std::string, double>>& fields) {
    return write(mac, [&](dnbridge_DeviceCommand& c) {
      dds::set_octets(c.outputs, outputs);
      if (fields.empty()) return;
      auto& seq = c.fields;
      seq._length = seq._maximum = static_cast<std::uint32_t>(fields.size());
      seq._release = true;
      seq._buffer = dds_sequence_dnbridge_DeviceFieldValue_allocbuf(fields.size());
      for (std::size_t i = 0; i < fields.size(); ++i) {
        seq._buffer[i].name = nullptr;
        dds::set_string(seq._buffer[i].name, fields[i].first);
        seq._buffer[i].value = fields[i].second;
      }
    });
  }
};

class DeviceTest : public BridgeTest {
 protected:
  // A pump at MAC 1 and the example I/O block at MAC 20 on port A.
  static daemon::DaemonConfig device_config() {
    auto c = daemon::parse_config(
        "rack = \"sim-rack\"\n"
        "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
        "[[port.node]]\nmac = 1\nname = \"pump-1\"\n"
        "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
        "eds = \"dnbridge-example-io-block.eds\"\n"
        "parameters = [ { name = \"Input filter\", value = 7 } ]\n"
        "safe_state_parameters = [ { name = \"Output fault action\", value = 0 },\n"
        "               { name = \"Output fault value\", value = 0 },\n"
        "               { name = \"Output idle action\", value = 0 },\n"
        "               { name = \"Output idle value\", value = 0x40 } ]\n",
        "device-test.toml", DNBRIDGE_EDS_DIR);
    c.domain_id = static_cast<std::uint32_t>(test_domain());
    return c;
  }

  void start_with_device() {
    ASSERT_NO_FATAL_FAILURE(make_bridge(device_config()));
    ASSERT_TRUE(devices_.matched(1));
    start_bridge();
    ASSERT_TRUE(devices_.until(
        [&] {
          const auto* s = devices_.latest(pump_mac(kDevice));
          return s && s->online && s->inputs_valid;
        },
        seconds(10)));
  }

  double device_param(unsigned n) {
    return on_port([n](sim::SimBackend& b) {
      return *b.eds_device(*devicenet::MacId::from(kDevice)).device().objects().param_number(n);
    });
  }
  bool echoes(std::uint8_t digital_outputs, std::string_view by) const {
    const auto* s = devices_.latest(pump_mac(kDevice));
    if (!s || s->outputs_idle || dds::view(s->commanded_by) != by) return false;
    const auto out = dds::view(s->outputs);
    return out.size() == 2 && out[0] == digital_outputs && s->output_fields._length == 1 &&
           s->output_fields._buffer[0].value == digital_outputs;
  }

  dds::Topic<dnbridge_DeviceState> device_topic_{supervisor_};
  Subscription<dnbridge_DeviceState> devices_{supervisor_, device_topic_, dds::state_reader_qos()};
};

TEST_F(DeviceTest, DeviceStateCarriesTheDataAndTheEdsFields) {
  ASSERT_NO_FATAL_FAILURE(start_with_device());
  const auto* s = devices_.latest(pump_mac(kDevice));
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(dds::view(s->name), "io-1");
  EXPECT_EQ(dds::view(s->product), "Example IO block 8DI/8DO/1AI");
  EXPECT_EQ(dds::view(s->inputs).size(), 4u);
  ASSERT_EQ(s->input_fields._length, 3u);
  EXPECT_EQ(dds::view(s->input_fields._buffer[2].name), "Analog input 1");
  EXPECT_EQ(dds::view(s->input_fields._buffer[2].type), "INT");
  EXPECT_EQ(dds::view(s->input_fields._buffer[2].units), "mV");
  EXPECT_EQ(s->input_fields._buffer[2].bit_offset, 16u);
  EXPECT_TRUE(s->outputs_idle);
  EXPECT_EQ(dds::view(s->idle_reason), "idle: no command yet");
  // The parameters and the safe state were downloaded.
  EXPECT_EQ(device_param(1), 7);
  EXPECT_EQ(device_param(9), 0x40);
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kDevice));
    return n && n->safe_state_known;
  }));
  const auto* n = nodes_.latest(pump_mac(kDevice));
  EXPECT_EQ(dds::view(n->safe_state_text),
            "Param6 Output fault action = 0; Param7 Output fault value = 0; Param8 Output idle "
            "action = 0; Param9 Output idle value = 64");
  EXPECT_EQ(n->vendor_id, 65001);
  EXPECT_EQ(n->produced_size, 4);
  EXPECT_EQ(n->consumed_size, 2);
}

TEST_F(DeviceTest, ADeviceCommandReachesTheDeviceAndItsDepartureLeavesTheIdleState) {
  ASSERT_NO_FATAL_FAILURE(start_with_device());
  auto supervisor = std::make_unique<Supervisor>("supervisor-d", 10);
  ASSERT_TRUE(supervisor->matched());
  ASSERT_TRUE(supervisor->write_fields(kDevice, {{"Digital outputs", 0x81}}));
  ASSERT_TRUE(devices_.until([&] { return echoes(0x81, "supervisor-d"); }));
  EXPECT_EQ(device_param(4), 0x81);
  ASSERT_TRUE(supervisor->write_bytes(kDevice, {0x03, 0x00}));
  ASSERT_TRUE(devices_.until([&] { return echoes(0x03, "supervisor-d"); }));
  EXPECT_EQ(device_param(4), 0x03);

  // Refused whole, the reason in NodeStatus.
  ASSERT_TRUE(supervisor->write_fields(kDevice, {{"Digital outputs", 300}}));
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kDevice));
    return n && n->counters.commands_refused == 1;
  }));
  EXPECT_EQ(dds::view(nodes_.latest(pump_mac(kDevice))->last_command_refused),
            "from supervisor-d: Digital outputs: 300 is outside 0..255");
  EXPECT_EQ(device_param(4), 0x03);

  // Bytes and fields both: refused whole.
  ASSERT_TRUE(supervisor->write_both(kDevice, {0x01, 0x00}, {{"Digital outputs", 1}}));
  ASSERT_TRUE(nodes_.until([&] {
    const auto* n = nodes_.latest(pump_mac(kDevice));
    return n && n->counters.commands_refused == 2;
  }));
  EXPECT_EQ(dds::view(nodes_.latest(pump_mac(kDevice))->last_command_refused),
            "from supervisor-d: outputs and fields both given: a command gives one");
  EXPECT_EQ(device_param(4), 0x03);

  // The commander goes: the device's configured idle state.
  supervisor.reset();
  ASSERT_TRUE(devices_.until(
      [&] {
        const auto* s = devices_.latest(pump_mac(kDevice));
        return s && s->outputs_idle && dds::view(s->idle_reason) == "idle: no live commander";
      },
      seconds(5)));
  EXPECT_EQ(device_param(4), 0x40);
}

TEST_F(DeviceTest, EachCommandTopicCommandsOnlyItsKindOfNode) {
  ASSERT_NO_FATAL_FAILURE(start_with_device());
  Supervisor devices("supervisor-d", 10);
  ASSERT_TRUE(devices.matched());
  ASSERT_TRUE(devices.write_bytes(1, {0x01, 0x00}));  // MAC 1 is a pump
  ASSERT_TRUE(devices_.until([&] {
    return log_.contains(LogLevel::kWarn,
                         "dnbridge/DeviceCommand sample from supervisor-d for port \"A\" MAC 1 "
                         "refused: the node's profile is \"cdn127\"");
  }));
  EXPECT_EQ(devices_.latest(pump_mac(1)), nullptr);  // no DeviceState for a pump
  ASSERT_TRUE(pumps_.until([&] { return pumps_.latest(pump_mac(1)) != nullptr; }));
  EXPECT_TRUE(pumps_.latest(pump_mac(1))->outputs_idle);
}

}  // namespace
}  // namespace dnbridge::e2e
