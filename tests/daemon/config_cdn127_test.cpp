// A CDN127 node's I/O configuration and the outputs' safe state in the rack
// file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "adapters/daemon/config.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "config_text.hpp"

namespace dnbridge::daemon {
namespace {

namespace cdn127 = profiles::cdn127;
using config_test::problems;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

const cdn127::IoConfiguration kCdn127 = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
const cdn127::IoConfiguration kCdn118 = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);

// ---------------------------------------------------------------------------
// I/O configurations.

cdn127::IoConfiguration io_of(std::string_view io_value) {
  const std::string text = std::string(ONE_PORT "[[port.node]]\nmac = 1\nname = \"p\"\nio = ") +
                           std::string(io_value) + "\n";
  return parse_config(text, "t.toml").ports.at(0).nodes.at(0).pump.io;
}

TEST(ConfigIo, PresetNamesAreTheDevicePresets) {
  EXPECT_EQ(io_of("\"cdn127\""), kCdn127);
  EXPECT_EQ(io_of("\"cdn118\""), kCdn118);
  EXPECT_NE(kCdn127, kCdn118);
}

TEST(ConfigIo, TableOverridesItsPreset) {
  EXPECT_EQ(io_of("{}"), kCdn127);
  EXPECT_EQ(io_of("{ preset = \"cdn118\" }"), kCdn118);
  cdn127::IoConfiguration expected = kCdn118;
  expected.num_analog_outputs = 0;
  expected.no_nc_mask = 0x05;
  EXPECT_EQ(io_of("{ preset = \"cdn118\", analog_outputs = 0, no_nc_mask = 0x05 }"), expected);
  EXPECT_EQ(io_of("{ mode = 0x80, digital_inputs = 4, digital_outputs = 2, analog_inputs = 0, "
                  "analog_outputs = 1, no_nc_mask = 255 }"),
            (cdn127::IoConfiguration{.mode = 0x80,
                                     .num_digital_inputs = 4,
                                     .num_digital_outputs = 2,
                                     .num_analog_inputs = 0,
                                     .num_analog_outputs = 1,
                                     .no_nc_mask = 0xFF}));
}

TEST(ConfigIo, DeviceMaximaAreAccepted) {
  EXPECT_EQ(io_of("{ digital_inputs = 8, digital_outputs = 8, analog_inputs = 2, "
                  "analog_outputs = 1 }"),
            kCdn127);
  EXPECT_EQ(io_of("{ digital_inputs = 0, digital_outputs = 0, analog_inputs = 0, "
                  "analog_outputs = 0 }")
                .num_digital_inputs,
            0);
}

TEST(ConfigIo, CountsOverTheDeviceMaximaAreRefusedOneByOne) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "io = { digital_inputs = 9, digital_outputs = 9, analog_inputs = 3, "
                              "analog_outputs = 2 }\n"),
            "t.toml:9:25: io.digital_inputs = 9 is more than a CDN127 has (at most 8)\n"
            "t.toml:9:46: io.digital_outputs = 9 is more than a CDN127 has (at most 8)\n"
            "t.toml:9:65: io.analog_inputs = 3 is more than a CDN127 has (at most 2)\n"
            "t.toml:9:85: io.analog_outputs = 2 is more than a CDN127 has (at most 1)");
}

TEST(ConfigIo, BadPresetTypeAndKeysAreErrors) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "io = \"cdn200\"\n"),
            "t.toml:9:6: io = \"cdn200\" is not a preset: use \"cdn127\" or \"cdn118\", or a table "
            "of Configuration object values");
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "io = 127\n"),
            "t.toml:9:6: io must be a preset name (\"cdn127\", \"cdn118\") or a table, not an "
            "integer");
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "io = { preset = \"x\", mode = 256, analog_input = 1 }\n"),
            "t.toml:9:17: io.preset = \"x\" is not a preset: use \"cdn127\" or \"cdn118\"\n"
            "t.toml:9:29: io.mode = 256 is out of range (0..255)\n"
            "t.toml:9:34: unknown key 'analog_input' in io (did you mean 'analog_inputs'?)");
}

TEST(ConfigIo, ReservedModeBitsLoadWithAWarning) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n"
                                      "io = { mode = 0x88 }\n",
                                      "t.toml");
  EXPECT_EQ(c.ports.at(0).nodes.at(0).pump.io.mode, 0x88);
  EXPECT_THAT(c.warnings, ElementsAre("t.toml:9:15: io.mode = 0x88 sets bits 3..6, which the "
                                      "CDN127 manual leaves reserved"));
}

// ---------------------------------------------------------------------------
// The outputs' safe state and the resume policy.

TEST(ConfigSafeState, DefaultIsEveryOutputOffOnFaultAndIdleDownloaded) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n",
                                      "t.toml");
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  EXPECT_EQ(n.pump.safe_state.source, cdn127::SafeStateSource::kConfiguration);
  EXPECT_EQ(n.pump.safe_state.values, cdn127::SafeState{});
  EXPECT_EQ(n.pump.safe_state.values.pump_fault, cdn127::DiscreteAction::kOff);
  EXPECT_EQ(n.pump.safe_state.values.analog_idle,
            (cdn127::AnalogAction{cdn127::AnalogAction::Kind::kValue, 0}));
  EXPECT_EQ(n.pump.resume, rack::ResumePolicy::kFreshCommand);
  EXPECT_TRUE(c.warnings.empty());
  // And the rack's scan list asks for them: DOP 1 and 2, AOP 1.
  const rack::PumpConfig p = to_pump_configs(c.ports.at(0)).at(0);
  EXPECT_EQ(p.safe_state.values, n.pump.safe_state.values);
  auto profile = cdn127::make_node_profile(p.io, p.safe_state);
  ASSERT_TRUE(profile.ok());
  unsigned dop = 0, aop = 0;
  for (const auto& s : profile->settings) {
    dop += s.class_id == cdn127::class_id::kDiscreteOutputPoint ? 1 : 0;
    aop += s.class_id == cdn127::class_id::kAnalogOutputPoint ? 1 : 0;
    EXPECT_FALSE(s.keep_device_value) << s.name;
  }
  EXPECT_EQ(dop, 8u);  // 2 instances x (fault, idle) x (value, action)
  EXPECT_EQ(aop, 4u);
}

TEST(ConfigSafeState, WordsAndVoltsFromDefaultsAndNodes) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n"
      "[defaults]\n"
      "pump_on_idle = \"hold\"\n"
      "analog_output_on_fault = 2.5\n"
      "[[port]]\n"
      "name = \"A\"\n"
      "interface = \"simulated\"\n"
      "bitrate = 500000\n"
      "[[port.node]]\n"
      "mac = 1\n"
      "name = \"p\"\n"
      "pump_on_fault = \"off\"\n"
      "n2_ballast_on_fault = \"on\"\n"
      "n2_ballast_on_idle = \"hold\"\n"
      "analog_output_on_idle = \"hold\"\n"
      "[[port.node]]\n"
      "mac = 2\n"
      "name = \"q\"\n"
      "pump_on_idle = \"off\"\n"
      "analog_output_on_fault = 10\n",
      "t.toml");
  const auto& p = c.ports.at(0).nodes.at(0).pump.safe_state.values;
  EXPECT_EQ(p.pump_fault, cdn127::DiscreteAction::kOff);
  EXPECT_EQ(p.pump_idle, cdn127::DiscreteAction::kHold);  // from [defaults]
  EXPECT_EQ(p.n2_ballast_fault, cdn127::DiscreteAction::kOn);
  EXPECT_EQ(p.n2_ballast_idle, cdn127::DiscreteAction::kHold);
  EXPECT_EQ(p.analog_fault, (cdn127::AnalogAction{cdn127::AnalogAction::Kind::kValue, 1024}));
  EXPECT_EQ(p.analog_idle, (cdn127::AnalogAction{cdn127::AnalogAction::Kind::kHold, 0}));
  const auto& q = c.ports.at(0).nodes.at(1).pump.safe_state.values;
  EXPECT_EQ(q.pump_idle, cdn127::DiscreteAction::kOff);  // its own over [defaults]
  EXPECT_EQ(q.analog_fault, (cdn127::AnalogAction{cdn127::AnalogAction::Kind::kValue, 4095}));
  EXPECT_EQ(q.analog_idle, (cdn127::AnalogAction{cdn127::AnalogAction::Kind::kValue, 0}));
}

TEST(ConfigSafeState, OptInsAreReadAndWarnedOf) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n"
                                      "safe_state = \"device\"\n"
                                      "resume = \"last-command\"\n",
                                      "t.toml");
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  EXPECT_EQ(n.pump.safe_state.source, cdn127::SafeStateSource::kDevice);
  EXPECT_EQ(n.pump.resume, rack::ResumePolicy::kLastCommand);
  EXPECT_THAT(c.warnings,
              ElementsAre("t.toml:9:14: node 1 keeps the device's own fault and idle actions "
                          "(safe_state = \"device\"): read and shown, never written",
                          "t.toml:10:10: node 1 drives its last outputs again after a loss "
                          "without a new command (resume = \"last-command\"): a pump may start on "
                          "its own after a power cycle"));
  // The device's values are read, none written.
  const rack::PumpConfig p = to_pump_configs(c.ports.at(0)).at(0);
  EXPECT_EQ(p.resume, rack::ResumePolicy::kLastCommand);
  auto profile = cdn127::make_node_profile(p.io, p.safe_state);
  ASSERT_TRUE(profile.ok());
  unsigned kept = 0;
  for (const auto& s : profile->settings) kept += s.keep_device_value ? 1 : 0;
  EXPECT_EQ(kept, 12u);
}

TEST(ConfigSafeState, MistakesAreErrorsWithTheirPosition) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "pump_on_fault = \"stop\"\n"
                              "pump_on_idle = true\n"
                              "analog_output_on_fault = 10.5\n"
                              "analog_output_on_idle = \"zero\"\n"
                              "safe_state = \"factory\"\n"
                              "resume = \"always\"\n"),
            "t.toml:9:17: pump_on_fault = \"stop\" is not an output action: use \"off\", \"on\" "
            "or \"hold\"\n"
            "t.toml:10:16: pump_on_idle must be a string, not a boolean\n"
            "t.toml:11:26: analog_output_on_fault = 10.5 V is out of range (0..10 V)\n"
            "t.toml:12:25: analog_output_on_idle = \"zero\" is not an analog output action: use "
            "a voltage (0..10, e.g. 0.0) or \"hold\"\n"
            "t.toml:13:14: safe_state = \"factory\" is not a choice: use \"configured\" (the "
            "default: the fault and idle actions this file gives are downloaded) or \"device\" "
            "(the device's own, fixed by its maker)\n"
            "t.toml:14:10: resume = \"always\" is not a policy: use \"new-command\" (the default) "
            "or \"last-command\"");
  // Values of a node that keeps the device's own: contradictory.
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "safe_state = \"device\"\n"
                              "pump_on_idle = \"off\"\n"),
            "t.toml:10:16: pump_on_idle has no effect with safe_state = \"device\": the device's "
            "own fault and idle actions are kept");
}

}  // namespace
}  // namespace dnbridge::daemon
