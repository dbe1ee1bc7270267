// cdn127-sim's device configuration (--device-config, --reading): what each
// key sets, how the layers combine, and every problem reported with its
// position.
#include "adapters/sim/host/device_config.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace dnbridge::sim::host {
namespace {

using devicenet::MacId;

constexpr sim::ClassAttribute kIdentityState{0x01, 8};

bool has_identity_state(const sim::SlaveOptions& o) {
  return std::find(o.unsupported_attributes.begin(), o.unsupported_attributes.end(),
                   kIdentityState) == o.unsupported_attributes.end();
}

// The problems a text is refused with.
std::vector<std::string> problems(std::string_view text) {
  try {
    (void)parse_device_config(text, "sim.toml");
  } catch (const DeviceConfigError& e) {
    return e.problems();
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return {};
}

MacId mac(unsigned v) { return MacId::from(v).value(); }

TEST(DeviceConfig, EveryKeySetsItsOption) {
  const DeviceConfig c = parse_device_config(R"(
[[device]]
mac = 5
configuration_locked_while_poll_allocated = true
poll_paths_fixed = true
idle_poll_answered_empty = true
no_ack_of_last_request_fragment = true
release_keeps_outputs = true
explicit_response_delay_ms = 300
poll_response_delay_ms = 3
serial_number_bytes = 4
identity_state_supported = false
epr_resolution_ms = 100
unsafe_factory_output_actions = true
)",
                                             "sim.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  EXPECT_EQ(c.devices[0].mac, mac(5));
  const auto all = device_options({}, c, Reading::kLenient);
  ASSERT_EQ(all.size(), 1u);
  const sim::SlaveOptions& o = all[0].cdn127;
  EXPECT_EQ(o.mac_switch, 5);
  EXPECT_EQ(o.serial_number, 0x10005u);
  EXPECT_TRUE(o.configuration_locked_while_poll_allocated);
  EXPECT_TRUE(o.poll_paths_fixed);
  EXPECT_TRUE(o.idle_poll_answered_empty);
  EXPECT_TRUE(o.no_ack_of_last_request_fragment);
  EXPECT_TRUE(o.release_keeps_outputs);
  EXPECT_EQ(o.explicit_response_delay, milliseconds(300));
  EXPECT_EQ(o.poll_response_delay, milliseconds(3));
  EXPECT_TRUE(o.serial_number_udint);
  EXPECT_FALSE(has_identity_state(o));
  EXPECT_EQ(o.timer_resolution, milliseconds(100));
  EXPECT_EQ(o.factory_output_actions, sim::kUnsafeFactoryOutputActions);
  EXPECT_EQ(describe_readings(o),
            "configuration locked while poll allocated, poll paths fixed, idle poll answered "
            "empty, no ack of last request fragment, outputs kept on release, explicit responses "
            "300 ms late, poll "
            "responses 3 ms late, 4-byte serial number, no Identity State, EPR in steps of 100 "
            "ms, unsafe factory output actions (every output holds on fault and idle)");
}

TEST(DeviceConfig, WithoutAFileEveryDeviceIsLenient) {
  const auto all = device_options({mac(1), mac(2)}, DeviceConfig{}, Reading::kLenient);
  ASSERT_EQ(all.size(), 2u);
  const sim::SlaveOptions lenient;
  for (const auto& spec : all) {
    const sim::SlaveOptions& o = spec.cdn127;
    EXPECT_FALSE(o.configuration_locked_while_poll_allocated);
    EXPECT_FALSE(o.poll_paths_fixed);
    EXPECT_FALSE(o.idle_poll_answered_empty);
    EXPECT_FALSE(o.no_ack_of_last_request_fragment);
    EXPECT_EQ(o.explicit_response_delay, Duration::zero());
    EXPECT_EQ(o.poll_response_delay, Duration::zero());
    EXPECT_FALSE(o.serial_number_udint);
    EXPECT_TRUE(has_identity_state(o));
    EXPECT_EQ(o.timer_resolution, lenient.timer_resolution);
    EXPECT_EQ(o.factory_output_actions, sim::OutputActions{});
    EXPECT_EQ(describe_readings(o), "lenient");
  }
}

// --reading field, then [defaults], then [[device]]; --mac devices first,
// then those only the file names; a MAC given both ways is one device.
TEST(DeviceConfig, LayersCombine) {
  const DeviceConfig c = parse_device_config(R"(
[defaults]
poll_response_delay_ms = 5
identity_state_supported = true

[[device]]
mac = 7
poll_paths_fixed = false
serial_number_bytes = 4

[[device]]
mac = 2
explicit_response_delay_ms = 0
)",
                                             "sim.toml");
  const auto all = device_options({mac(2), mac(3)}, c, Reading::kField);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].cdn127.mac_switch, 2);
  EXPECT_EQ(all[1].cdn127.mac_switch, 3);
  EXPECT_EQ(all[2].cdn127.mac_switch, 7);
  for (const auto& spec : all) {
    const sim::SlaveOptions& o = spec.cdn127;
    EXPECT_TRUE(o.configuration_locked_while_poll_allocated);  // the reading
    EXPECT_TRUE(o.idle_poll_answered_empty);
    EXPECT_EQ(o.timer_resolution, milliseconds(100));
    EXPECT_EQ(o.poll_response_delay, milliseconds(5));  // [defaults] over the reading
    EXPECT_TRUE(has_identity_state(o));
  }
  EXPECT_EQ(all[0].cdn127.explicit_response_delay, Duration::zero());  // [[device]] over both
  EXPECT_EQ(all[1].cdn127.explicit_response_delay, milliseconds(300));
  EXPECT_TRUE(all[1].cdn127.poll_paths_fixed);
  EXPECT_FALSE(all[2].cdn127.poll_paths_fixed);
  EXPECT_FALSE(all[1].cdn127.serial_number_udint);
  EXPECT_TRUE(all[2].cdn127.serial_number_udint);
}

TEST(DeviceConfig, FieldReadingIsTheStrictestDevice) {
  const auto all = device_options({mac(4)}, DeviceConfig{}, Reading::kField);
  ASSERT_EQ(all.size(), 1u);
  const sim::SlaveOptions& o = all[0].cdn127;
  EXPECT_TRUE(o.configuration_locked_while_poll_allocated);
  EXPECT_TRUE(o.poll_paths_fixed);
  EXPECT_TRUE(o.idle_poll_answered_empty);
  EXPECT_TRUE(o.no_ack_of_last_request_fragment);
  EXPECT_EQ(o.explicit_response_delay, milliseconds(300));
  EXPECT_EQ(o.poll_response_delay, milliseconds(3));
  EXPECT_FALSE(o.serial_number_udint);
  EXPECT_FALSE(has_identity_state(o));
  EXPECT_EQ(o.timer_resolution, milliseconds(100));
  // Values in E2, not a reading: the field reading leaves them alone.
  EXPECT_EQ(o.factory_output_actions, sim::OutputActions{});
}

// [defaults] gives every device the unsafe actions; a [[device]] false takes
// them back to the simulator's own.
TEST(DeviceConfig, UnsafeFactoryOutputActionsLayer) {
  const DeviceConfig c = parse_device_config(R"(
[defaults]
unsafe_factory_output_actions = true

[[device]]
mac = 8
unsafe_factory_output_actions = false
)",
                                             "sim.toml");
  const auto all = device_options({mac(1)}, c, Reading::kField);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].cdn127.factory_output_actions, sim::kUnsafeFactoryOutputActions);
  EXPECT_EQ(all[1].cdn127.factory_output_actions, sim::OutputActions{});
  const auto lenient = device_options({mac(1)}, DeviceConfig{}, Reading::kLenient);
  ASSERT_EQ(lenient.size(), 1u);
  EXPECT_EQ(describe_readings(lenient[0].cdn127), "lenient");
  EXPECT_EQ(problems("[defaults]\nunsafe_factory_output_actions = 1\n"),
            (std::vector<std::string>{
                "sim.toml:2:33: unsafe_factory_output_actions must be true or false, not an "
                "integer"}));
}

TEST(DeviceConfig, TheShippedExampleLoads) {
  const DeviceConfig c =
      load_device_config(DNBRIDGE_SOURCE_DIR "/deploy/config/cdn127-sim-example.toml");
  EXPECT_FALSE(c.devices.empty());
  const auto all = device_options({}, c, Reading::kLenient);
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [](const DeviceSpec& d) {
    return d.cdn127.factory_output_actions == sim::kUnsafeFactoryOutputActions;
  }));
}

TEST(DeviceConfig, ADeviceWithAnEdsFileRunsIt) {
  const DeviceConfig c = parse_device_config(
      "[defaults]\npoll_paths_fixed = true\n"
      "[[device]]\nmac = 21\neds = \"dnbridge-example-io-block.eds\"\nserial_number = 7\n"
      "member_lists = false\n",
      "sim.toml", DNBRIDGE_SOURCE_DIR "/deploy/eds");
  const auto all = device_options({mac(1)}, c, Reading::kLenient);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_FALSE(all[0].eds.has_value());
  ASSERT_TRUE(all[1].eds.has_value());
  EXPECT_EQ(all[1].eds->file->device.product_name, "Example IO block 8DI/8DO/1AI");
  EXPECT_EQ(all[1].eds->path, DNBRIDGE_SOURCE_DIR "/deploy/eds/dnbridge-example-io-block.eds");
  EXPECT_EQ(all[1].eds_options.mac, 21);
  EXPECT_EQ(all[1].eds_options.serial_number, 7u);
  EXPECT_FALSE(all[1].eds_options.member_lists);

  // The CDN127's readings are not its own; its EDS's problems have their lines.
  EXPECT_EQ(problems("[[device]]\nmac = 21\neds = \"x.eds\"\npoll_paths_fixed = true\nfoo = 1\n"),
            (std::vector<std::string>{
                "sim.toml:3:7: eds: x.eds: cannot open: No such file or directory",
                "sim.toml:4:20: poll_paths_fixed is a CDN127 reading: this device runs its EDS "
                "file",
                "sim.toml:5:1: unknown key 'foo' in [[device]]"}));
}

TEST(DeviceConfig, EmptyFileIsNoChange) {
  const DeviceConfig c = parse_device_config("", "sim.toml");
  EXPECT_TRUE(c.devices.empty());
  EXPECT_FALSE(c.defaults.poll_paths_fixed.has_value());
}

TEST(DeviceConfig, UnknownKeysAreRefusedWithTheirPosition) {
  EXPECT_EQ(problems("[[device]]\nmac = 5\npoll_path_fixed = true\n"),
            (std::vector<std::string>{
                "sim.toml:3:1: unknown key 'poll_path_fixed' in [[device]] (did you mean "
                "'poll_paths_fixed'?)"}));
  EXPECT_EQ(problems("[defaults]\nmac = 5\n"),
            (std::vector<std::string>{"sim.toml:2:1: unknown key 'mac' in [defaults]"}));
  EXPECT_EQ(problems("verbose = true\n"),
            (std::vector<std::string>{
                "sim.toml:1:1: unknown key 'verbose' in the device configuration"}));
}

TEST(DeviceConfig, BadValuesAreRefusedWithTheirLine) {
  // Every problem at once, in the file's order.
  EXPECT_EQ(problems(R"([defaults]
poll_paths_fixed = "yes"
explicit_response_delay_ms = -1

[[device]]
mac = 64
serial_number_bytes = 3

[[device]]
epr_resolution_ms = 0

[[device]]
mac = 9

[[device]]
mac = 9
poll_response_delay_ms = 1.5
)"),
            (std::vector<std::string>{
                "sim.toml:2:20: poll_paths_fixed must be true or false, not a string",
                "sim.toml:3:30: explicit_response_delay_ms = -1 is out of range (0..60000 ms)",
                "sim.toml:6:7: mac = 64 is out of range (0..63)",
                "sim.toml:7:23: serial_number_bytes = 3: 2 (UINT, as the manual's table types "
                "it) or 4 (UDINT, as ODVA's Identity)",
                "sim.toml:9:1: missing required key 'mac' in [[device]]",
                "sim.toml:10:21: epr_resolution_ms = 0 is out of range (1..65535 ms)",
                "sim.toml:16:7: mac = 9 is given twice (first on line 13)",
                "sim.toml:17:26: poll_response_delay_ms must be an integer, not a floating-point "
                "number",
            }));
}

TEST(DeviceConfig, WrongShapesAndSyntax) {
  EXPECT_EQ(problems("[device]\nmac = 5\n"),
            (std::vector<std::string>{
                "sim.toml:1:1: device must be an array of tables ([[device]]), not a table"}));
  EXPECT_EQ(problems("defaults = 3\n"),
            (std::vector<std::string>{
                "sim.toml:1:12: defaults must be a table ([defaults]), not an integer"}));
  const auto syntax = problems("[[device]]\nmac = \n");
  ASSERT_EQ(syntax.size(), 1u);
  EXPECT_EQ(syntax[0].rfind("sim.toml:2:", 0), 0u) << syntax[0];
}

TEST(DeviceConfig, MissingFileIsAProblemNotACrash) {
  try {
    (void)load_device_config("/nonexistent/cdn127-sim.toml");
    ADD_FAILURE() << "loaded";
  } catch (const DeviceConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].rfind("/nonexistent/cdn127-sim.toml: cannot open", 0), 0u);
  }
}

}  // namespace
}  // namespace dnbridge::sim::host
