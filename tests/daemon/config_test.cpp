#include "adapters/daemon/config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "adapters/daemon/host_identity.hpp"
#include "bridge/profiles/cdn127/node_profile.hpp"
#include "bridge/profiles/cdn127/objects.hpp"
#include "bridge/rack/pump_rack.hpp"

namespace dnbridge::daemon {
namespace {

namespace cdn127 = profiles::cdn127;
using devicenet::MacId;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

MacId mac(unsigned v) { return MacId::from(v).value(); }

const cdn127::IoConfiguration kCdn127 = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
const cdn127::IoConfiguration kCdn118 = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);

// The problems parse_config reports for `text`, one per line, or "(none)".
std::string problems(std::string_view text) {
  try {
    parse_config(text, "t.toml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(none)";
}

// Lines 1..5 of most texts below: a rack with one simulated port.
#define ONE_PORT                \
  "rack = \"r\"\n"              \
  "[[port]]\n"                  \
  "name = \"A\"\n"              \
  "interface = \"simulated\"\n" \
  "bitrate = 500000\n"

// ---------------------------------------------------------------------------
// Files that load.

TEST(ConfigFile, ExampleLoadsWithEveryValueWhereItWasWritten) {
  const std::string path = DNBRIDGE_SOURCE_DIR "/deploy/config/rack-example.toml";
  const DaemonConfig c = load_config_file(path);
  EXPECT_EQ(c.source, path);
  EXPECT_EQ(c.rack, "etch-3-rack-A");
  EXPECT_EQ(c.domain_id, 0u);
  EXPECT_EQ(c.master_mac, mac(0));
  EXPECT_EQ(c.log_level, LogLevel::kInfo);
  EXPECT_TRUE(c.warnings.empty());
  ASSERT_EQ(c.ports.size(), 2u);

  const PortConfig& a = c.ports[0];
  EXPECT_EQ(a.name, "A");
  EXPECT_EQ(a.interface, "can0");
  EXPECT_EQ(a.bitrate, 500000u);
  EXPECT_EQ(a.master.master_mac, mac(0));
  EXPECT_EQ(a.master.vendor_id, 0u);
  EXPECT_EQ(a.master_serial_number, std::nullopt);  // derived from the host
  ASSERT_EQ(a.nodes.size(), 3u);
  EXPECT_EQ(a.nodes[0].pump.node.mac, mac(1));
  EXPECT_EQ(a.nodes[0].pump.node.name, "chamber-1-dry-pump");
  EXPECT_EQ(a.nodes[0].profile, "cdn127");
  EXPECT_EQ(a.nodes[0].pump.io, kCdn127);
  EXPECT_EQ(a.nodes[0].pump.node.poll_period, milliseconds(100));           // [defaults]
  EXPECT_EQ(a.nodes[0].pump.node.expected_packet_rate, milliseconds(500));  // [defaults]
  EXPECT_EQ(a.nodes[0].pump.no_commander, NoCommanderPolicy::kIdle);
  EXPECT_FALSE(a.nodes[0].pump.identity.has_value());
  EXPECT_EQ(a.nodes[1].pump.io, kCdn118);
  EXPECT_EQ(a.nodes[2].pump.node.name, "loadlock-pump");
  EXPECT_EQ(a.nodes[2].pump.io, (cdn127::IoConfiguration{.mode = 0x86,
                                                         .num_digital_inputs = 8,
                                                         .num_digital_outputs = 3,
                                                         .num_analog_inputs = 1,
                                                         .num_analog_outputs = 0,
                                                         .no_nc_mask = 0}));
  EXPECT_EQ(a.nodes[2].pump.no_commander, NoCommanderPolicy::kHoldLastOutputs);

  const PortConfig& b = c.ports[1];
  EXPECT_EQ(b.name, "B");
  EXPECT_EQ(b.interface, "can1");
  EXPECT_EQ(b.bitrate, 250000u);
  EXPECT_EQ(b.master.master_mac, mac(62));
  ASSERT_EQ(b.nodes.size(), 2u);
  EXPECT_EQ(b.nodes[0].pump.node.mac, mac(10));
  EXPECT_EQ(b.nodes[0].pump.node.poll_period, milliseconds(200));
  EXPECT_EQ(b.nodes[0].pump.node.expected_packet_rate, milliseconds(1000));
  EXPECT_DOUBLE_EQ(b.nodes[0].publish.analog_deadband_volts, 0.1);
  EXPECT_DOUBLE_EQ(b.nodes[1].publish.analog_deadband_volts, 0.05);  // [defaults]
  EXPECT_EQ(b.nodes[1].pump.io, kCdn118);
  EXPECT_EQ(
      b.nodes[1].pump.identity,
      (devicenet::ExpectedIdentity{.vendor_id = 59, .product_type = 27, .product_code = 1888}));
}

TEST(ConfigFile, EmbeddedDefaultIsTheShippedFile) {
  std::ifstream in(DNBRIDGE_SOURCE_DIR "/deploy/config/default.toml", std::ios::binary);
  ASSERT_TRUE(in);
  std::ostringstream file;
  file << in.rdbuf();
  EXPECT_EQ(embedded_default_config_text(), file.str());
  EXPECT_EQ(load_config_file(DNBRIDGE_SOURCE_DIR "/deploy/config/default.toml").rack, "sim-rack");
}

TEST(ConfigFile, EmbeddedDefaultIsTheSimulatedRack) {
  const DaemonConfig c = embedded_default_config();
  EXPECT_EQ(c.source, "embedded default");
  EXPECT_EQ(c.rack, "sim-rack");
  EXPECT_EQ(c.domain_id, 0u);
  EXPECT_EQ(c.master_mac, mac(0));
  EXPECT_TRUE(c.warnings.empty());
  ASSERT_EQ(c.ports.size(), 1u);
  const PortConfig& p = c.ports[0];
  EXPECT_EQ(p.name, "A");
  EXPECT_EQ(p.interface, kSimulatedInterface);
  EXPECT_EQ(p.bitrate, 500000u);
  EXPECT_EQ(p.master.master_mac, mac(0));
  ASSERT_EQ(p.nodes.size(), 8u);
  for (unsigned i = 0; i < 8; ++i) {
    SCOPED_TRACE(i);
    const NodeSettings& n = p.nodes[i];
    EXPECT_EQ(n.pump.node.mac, mac(i + 1));
    EXPECT_EQ(n.pump.node.name, "pump-" + std::to_string(i + 1));
    EXPECT_EQ(n.pump.io, i == 7 ? kCdn118 : kCdn127);
    EXPECT_EQ(n.pump.node.poll_period, milliseconds(100));
    EXPECT_EQ(n.pump.node.expected_packet_rate, milliseconds(500));
  }
}

TEST(ConfigFile, EmbeddedDefaultTextIsWhatItRuns) {
  const DaemonConfig printed = parse_config(embedded_default_config_text(), "printed.toml");
  const DaemonConfig embedded = embedded_default_config();
  ASSERT_EQ(printed.ports.size(), embedded.ports.size());
  ASSERT_EQ(printed.ports[0].nodes.size(), embedded.ports[0].nodes.size());
  for (std::size_t i = 0; i < printed.ports[0].nodes.size(); ++i) {
    EXPECT_EQ(printed.ports[0].nodes[i].pump.node.mac, embedded.ports[0].nodes[i].pump.node.mac);
    EXPECT_EQ(printed.ports[0].nodes[i].pump.io, embedded.ports[0].nodes[i].pump.io);
  }
}

TEST(ConfigFile, MinimalFileTakesTheBuiltInDefaults) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 5\n"
                                      "name = \"p\"\n",
                                      "t.toml");
  EXPECT_EQ(c.domain_id, 0u);
  EXPECT_EQ(c.log_level, LogLevel::kInfo);
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  const devicenet::NodeConfig scan_list_defaults;
  EXPECT_EQ(n.profile, "cdn127");
  EXPECT_EQ(n.pump.io, kCdn127);
  EXPECT_EQ(n.pump.node.poll_period, scan_list_defaults.poll_period);
  EXPECT_EQ(n.pump.node.expected_packet_rate, scan_list_defaults.expected_packet_rate);
  EXPECT_EQ(n.pump.node.explicit_packet_rate, scan_list_defaults.explicit_packet_rate);
  EXPECT_EQ(n.pump.node.immediate_poll_on_change, scan_list_defaults.immediate_poll_on_change);
  EXPECT_EQ(n.publish, PublishPolicy{});
  EXPECT_EQ(n.pump.no_commander, NoCommanderPolicy::kIdle);
  const devicenet::ScannerConfig scanner_defaults;
  const devicenet::ScannerConfig& t = c.ports[0].master;
  EXPECT_EQ(t.allocate_retry_min, scanner_defaults.allocate_retry_min);
  EXPECT_EQ(t.allocate_retry_max, scanner_defaults.allocate_retry_max);
  EXPECT_EQ(t.fault_recheck, scanner_defaults.fault_recheck);
  EXPECT_EQ(t.poll_response_timeout, scanner_defaults.poll_response_timeout);
  EXPECT_EQ(t.explicit_messaging.response_timeout,
            scanner_defaults.explicit_messaging.response_timeout);
  EXPECT_EQ(t.max_consecutive_errors, scanner_defaults.max_consecutive_errors);
  EXPECT_EQ(t.poll_batch_window, scanner_defaults.poll_batch_window);
}

TEST(ConfigFile, NodeSettingsOverrideDefaults) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n"
      "log_level = \"debug\"\n"
      "domain = 7\n"
      "[defaults]\n"
      "poll_period_ms = 50\n"
      "expected_packet_rate_ms = 400\n"
      "explicit_packet_rate_ms = 3000\n"
      "immediate_poll = false\n"
      "publish_max_period_ms = 2000\n"
      "analog_deadband_volts = 1\n"
      "no_commander = \"hold\"\n"
      "io = \"cdn118\"\n"
      "[[port]]\n"
      "name = \"A\"\n"
      "interface = \"vcan0\"\n"
      "bitrate = 125000\n"
      "master_vendor_id = 1234\n"
      "master_serial_number = 0xDB000001\n"
      "allocate_retry_min_ms = 100\n"
      "allocate_retry_max_ms = 800\n"
      "fault_recheck_ms = 3000\n"
      "poll_response_timeout_ms = 20\n"
      "poll_batch_ms = 0\n"
      "explicit_response_timeout_ms = 1500\n"
      "scan_response_timeout_ms = 300\n"
      "max_consecutive_errors = 4\n"
      "[[port.node]]\n"
      "mac = 1\n"
      "name = \"inherits\"\n"
      "[[port.node]]\n"
      "mac = 2\n"
      "name = \"overrides\"\n"
      "poll_period_ms = 25\n"
      "expected_packet_rate_ms = 100\n"
      "explicit_packet_rate_ms = 1000\n"
      "immediate_poll = true\n"
      "publish_max_period_ms = 500\n"
      "analog_deadband_volts = 0.25\n"
      "no_commander = \"idle\"\n"
      "io = \"cdn127\"\n",
      "t.toml");
  EXPECT_EQ(c.log_level, LogLevel::kDebug);
  EXPECT_EQ(c.domain_id, 7u);
  const PortConfig& p = c.ports.at(0);
  EXPECT_EQ(p.bitrate, 125000u);
  EXPECT_EQ(p.master.vendor_id, 1234u);
  EXPECT_EQ(p.master_serial_number, 0xDB000001u);
  EXPECT_EQ(p.master.allocate_retry_min, milliseconds(100));
  EXPECT_EQ(p.master.allocate_retry_max, milliseconds(800));
  EXPECT_EQ(p.master.fault_recheck, milliseconds(3000));
  EXPECT_EQ(p.master.poll_response_timeout, milliseconds(20));
  EXPECT_EQ(p.master.poll_batch_window, Duration::zero());
  EXPECT_EQ(p.master.explicit_messaging.response_timeout, milliseconds(1500));
  EXPECT_EQ(p.master.scan_response_timeout, milliseconds(300));
  EXPECT_EQ(p.master.max_consecutive_errors, 4u);

  const NodeSettings& a = p.nodes.at(0);
  EXPECT_EQ(a.pump.node.poll_period, milliseconds(50));
  EXPECT_EQ(a.pump.node.expected_packet_rate, milliseconds(400));
  EXPECT_EQ(a.pump.node.explicit_packet_rate, milliseconds(3000));
  EXPECT_FALSE(a.pump.node.immediate_poll_on_change);
  EXPECT_EQ(a.publish.max_period, milliseconds(2000));
  EXPECT_DOUBLE_EQ(a.publish.analog_deadband_volts, 1.0);
  EXPECT_EQ(a.pump.no_commander, NoCommanderPolicy::kHoldLastOutputs);
  EXPECT_EQ(a.pump.io, kCdn118);

  const NodeSettings& b = p.nodes.at(1);
  EXPECT_EQ(b.pump.node.poll_period, milliseconds(25));
  EXPECT_EQ(b.pump.node.expected_packet_rate, milliseconds(100));
  EXPECT_EQ(b.pump.node.explicit_packet_rate, milliseconds(1000));
  EXPECT_TRUE(b.pump.node.immediate_poll_on_change);
  EXPECT_EQ(b.publish.max_period, milliseconds(500));
  EXPECT_DOUBLE_EQ(b.publish.analog_deadband_volts, 0.25);
  EXPECT_EQ(b.pump.no_commander, NoCommanderPolicy::kIdle);
  EXPECT_EQ(b.pump.io, kCdn127);
}

TEST(ConfigFile, MissingFileIsReportedWithItsName) {
  try {
    load_config_file("/nonexistent/dnbridge/rack.toml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/dnbridge/rack.toml: cannot open: No such file or directory");
  }
}

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
// Errors, each with its position and text.

TEST(ConfigErrors, TomlSyntaxErrorHasItsPosition) {
  // The text after the position is toml++'s own.
  const std::string p = problems("rack = \"r\"\nbitrate = = 2\n");
  EXPECT_THAT(p, ::testing::StartsWith("t.toml:2:11: "));
  EXPECT_THAT(p, HasSubstr("could not determine value type"));
  EXPECT_THAT(p, Not(HasSubstr("\n")));  // the first syntax error only
  const std::string redefined = problems("rack = \"r\"\nrack = \"s\"\n");
  EXPECT_THAT(redefined, ::testing::StartsWith("t.toml:2:8: "));
  EXPECT_THAT(redefined, HasSubstr("cannot redefine existing string 'rack'"));
}

TEST(ConfigErrors, UnknownKeysAreNamedWithASuggestion) {
  EXPECT_EQ(
      problems("rack = \"r\"\n"
               "colour = \"blue\"\n"
               "[defaults]\n"
               "pollperiod_ms = 100\n"
               "[[port]]\n"
               "name = \"A\"\n"
               "interface = \"simulated\"\n"
               "bitrate = 500000\n"
               "bit_rate = 500000\n"
               "[[port.node]]\n"
               "mac = 1\n"
               "name = \"p\"\n"
               "  poll_perod_ms = 100\n"
               "identity = { vendor_id = 1, product_type = 2, product_code = 3, rev = 1 }\n"),
      "t.toml:2:1: unknown key 'colour' in the top level\n"
      "t.toml:4:1: unknown key 'pollperiod_ms' in [defaults] (did you mean 'poll_period_ms'?)\n"
      "t.toml:9:1: unknown key 'bit_rate' in [[port]] (did you mean 'bitrate'?)\n"
      "t.toml:13:3: unknown key 'poll_perod_ms' in [[port.node]] (did you mean "
      "'poll_period_ms'?)\n"
      "t.toml:14:65: unknown key 'rev' in identity");
}

TEST(ConfigErrors, MacAndNameOnlyInNodesNotInDefaults) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "[defaults]\n"
                              "mac = 3\n"
                              "name = \"x\"\n"),
            "t.toml:10:1: mac stands in a [[port.node]] table only, not in [defaults]\n"
            "t.toml:11:1: name stands in a [[port.node]] table only, not in [defaults]");
}

// A serial number belongs to one device: never in [defaults].
TEST(ConfigErrors, SerialOnlyInNodesNotInDefaults) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "serial = 0x1_0000_0000\n"
                              "[defaults]\n"
                              "serial = 3\n"),
            "t.toml:9:10: serial = 4294967296 is out of range (0..4294967295)\n"
            "t.toml:11:1: serial stands in a [[port.node]] table only, not in [defaults]");
}

TEST(ConfigFile, SerialAndTimeoutsOfASlowDevice) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "explicit_response_timeout_ms = 1500\n"
                                      "[defaults]\n"
                                      "poll_response_timeout_ms = 30\n"
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n"
                                      "serial = 0x1234\n"
                                      "explicit_response_timeout_ms = 2500\n"
                                      "[[port.node]]\n"
                                      "mac = 2\n"
                                      "name = \"q\"\n",
                                      "t.toml");
  const auto& nodes = c.ports.at(0).nodes;
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[0].pump.node.serial_number, 0x1234u);
  EXPECT_EQ(nodes[0].pump.node.explicit_response_timeout, milliseconds(2500));
  EXPECT_EQ(nodes[0].pump.node.poll_response_timeout, milliseconds(30));
  EXPECT_EQ(nodes[1].pump.node.serial_number, std::nullopt);
  // Node 2 keeps the port's explicit timeout (no override of its own).
  EXPECT_EQ(nodes[1].pump.node.explicit_response_timeout, std::nullopt);
  EXPECT_EQ(nodes[1].pump.node.poll_response_timeout, milliseconds(30));
  EXPECT_EQ(c.ports.at(0).master.explicit_messaging.response_timeout, milliseconds(1500));
  const rack::PumpConfig p = to_pump_configs(c.ports.at(0)).at(0);
  EXPECT_EQ(p.node.serial_number, 0x1234u);
  EXPECT_EQ(p.node.explicit_response_timeout, milliseconds(2500));
  EXPECT_EQ(p.node.poll_response_timeout, milliseconds(30));
}

TEST(ConfigErrors, WrongTypes) {
  EXPECT_EQ(problems("rack = 5\n"
                     "domain = \"0\"\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500e3\n"
                     "[[port.node]]\n"
                     "mac = \"1\"\n"
                     "name = \"p\"\n"
                     "immediate_poll = \"yes\"\n"
                     "analog_deadband_volts = \"0.1\"\n"
                     "identity = 59\n"
                     "[[port.node]]\n"
                     "mac = 2\n"
                     "name = \"q\"\n"
                     "poll_period_ms = 100.0\n"),
            "t.toml:1:8: rack must be a string, not an integer\n"
            "t.toml:2:10: domain must be an integer, not a string\n"
            "t.toml:6:11: bitrate must be an integer, not a floating-point number\n"
            "t.toml:8:7: mac must be an integer, not a string\n"
            "t.toml:10:18: immediate_poll must be true or false, not a string\n"
            "t.toml:11:25: analog_deadband_volts must be a number, not a string\n"
            "t.toml:12:12: identity must be a table { vendor_id, product_type, product_code }, "
            "not an integer\n"
            "t.toml:16:18: poll_period_ms must be an integer, not a floating-point number");
}

TEST(ConfigErrors, OutOfRangeValues) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "domain = 233\n"
                     "master_mac = -1\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 300000\n"
                     "master_vendor_id = 65536\n"
                     "[[port.node]]\n"
                     "mac = 64\n"
                     "name = \"p\"\n"
                     "poll_period_ms = 0\n"
                     "analog_deadband_volts = -0.5\n"
                     "explicit_packet_rate_ms = 65536\n"
                     "identity = { vendor_id = 59, product_type = 27, product_code = 70000 }\n"),
            "t.toml:2:10: domain = 233 is out of range: a DDS domain ID is 0..232\n"
            "t.toml:3:14: master_mac = -1 is out of range: a DeviceNet MAC ID is 0..63\n"
            "t.toml:7:11: bitrate = 300000 is not a DeviceNet bit rate: use 125000, 250000 or "
            "500000\n"
            "t.toml:8:20: master_vendor_id = 65536 is out of range (0..65535)\n"
            "t.toml:10:7: mac = 64 is out of range: a DeviceNet MAC ID is 0..63\n"
            "t.toml:12:18: poll_period_ms = 0 is out of range (1..65535 ms)\n"
            "t.toml:13:25: analog_deadband_volts = -0.5 is out of range (0..10 V)\n"
            "t.toml:14:27: explicit_packet_rate_ms = 65536 is out of range (1..65535 ms)\n"
            "t.toml:15:64: identity.product_code = 70000 is out of range (0..65535)");
}

TEST(ConfigErrors, ExpectedPacketRateShorterThanThePollPeriod) {
  // Both on the node: at the expected packet rate.
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "poll_period_ms = 100\n"
                              "expected_packet_rate_ms = 50\n"),
            "t.toml:10:27: expected_packet_rate_ms = 50 is shorter than poll_period_ms = 100: the "
            "node expects a poll at least once per expected packet rate");
  // The poll period on the node, the rate from [defaults]: at the poll period,
  // saying where the rate came from.
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[defaults]\n"
                     "expected_packet_rate_ms = 200\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"p\"\n"
                     "poll_period_ms = 300\n"),
            "t.toml:11:18: expected_packet_rate_ms = 200 (from [defaults], line 3) is shorter "
            "than poll_period_ms = 300: the node expects a poll at least once per expected packet "
            "rate");
  // Against the built-in rate (1000 ms).
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "poll_period_ms = 2000\n"),
            "t.toml:9:18: expected_packet_rate_ms = 1000 (the default) is shorter than "
            "poll_period_ms = 2000: the node expects a poll at least once per expected packet "
            "rate");
  // Equal is fine.
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "poll_period_ms = 100\n"
                              "expected_packet_rate_ms = 100\n"),
            "(none)");
}

TEST(ConfigFile, ImmediatePollMinGapFromDefaultsNodesAndTheBuiltInValue) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n"
      "[defaults]\n"
      "immediate_poll_min_gap_ms = 20\n"
      "[[port]]\n"
      "name = \"A\"\n"
      "interface = \"simulated\"\n"
      "bitrate = 500000\n"
      "[[port.node]]\n"
      "mac = 1\n"
      "name = \"inherits\"\n"
      "[[port.node]]\n"
      "mac = 2\n"
      "name = \"every change at once\"\n"
      "immediate_poll_min_gap_ms = 0\n"
      "[[port.node]]\n"
      "mac = 3\n"
      "name = \"a poll period\"\n"
      "poll_period_ms = 50\n"
      "immediate_poll_min_gap_ms = 50\n",
      "t.toml");
  const auto& nodes = c.ports.at(0).nodes;
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_EQ(nodes[0].pump.node.immediate_poll_min_gap, milliseconds(20));
  EXPECT_EQ(nodes[1].pump.node.immediate_poll_min_gap, Duration::zero());
  EXPECT_EQ(nodes[2].pump.node.immediate_poll_min_gap, milliseconds(50));
  EXPECT_EQ(to_pump_configs(c.ports.at(0)).at(0).node.immediate_poll_min_gap, milliseconds(20));

  // Not given: the built-in 10 ms, or the poll period where that is shorter.
  const DaemonConfig d = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n"
                                      "[[port.node]]\n"
                                      "mac = 2\n"
                                      "name = \"q\"\n"
                                      "poll_period_ms = 4\n",
                                      "t.toml");
  EXPECT_EQ(d.ports.at(0).nodes.at(0).pump.node.immediate_poll_min_gap,
            devicenet::NodeConfig{}.immediate_poll_min_gap);
  EXPECT_EQ(devicenet::NodeConfig{}.immediate_poll_min_gap, milliseconds(10));
  EXPECT_EQ(d.ports.at(0).nodes.at(1).pump.node.immediate_poll_min_gap, milliseconds(4));
}

TEST(ConfigErrors, ImmediatePollMinGapNegativeOrLongerThanThePollPeriod) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "immediate_poll_min_gap_ms = -1\n"),
            "t.toml:9:29: immediate_poll_min_gap_ms = -1 is out of range (0..65535 ms)");
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "poll_period_ms = 100\n"
                              "immediate_poll_min_gap_ms = 150\n"),
            "t.toml:10:29: immediate_poll_min_gap_ms = 150 is longer than poll_period_ms = 100: "
            "polls for changed outputs may be held back at most a poll period");
  // Against the built-in poll period (100 ms).
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "immediate_poll_min_gap_ms = 101\n"),
            "t.toml:9:29: immediate_poll_min_gap_ms = 101 is longer than poll_period_ms = 100 "
            "(the default): polls for changed outputs may be held back at most a poll period");
  // The gap from [defaults], a node's shorter period: at the period.
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[defaults]\n"
                     "immediate_poll_min_gap_ms = 20\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"p\"\n"
                     "poll_period_ms = 10\n"),
            "t.toml:11:18: immediate_poll_min_gap_ms = 20 (from [defaults], line 3) is longer "
            "than poll_period_ms = 10: polls for changed outputs may be held back at most a poll "
            "period");
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "immediate_poll_min_gap_ms = 2.5\n"),
            "t.toml:9:29: immediate_poll_min_gap_ms must be an integer, not a floating-point "
            "number");
}

TEST(ConfigErrors, ProblemInDefaultsIsReportedOnceForAllNodes) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[defaults]\n"
                     "poll_period_ms = 400\n"
                     "expected_packet_rate_ms = 300\n"
                     "no_commander = \"stop\"\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"p\"\n"
                     "[[port.node]]\n"
                     "mac = 2\n"
                     "name = \"q\"\n"),
            "t.toml:4:27: expected_packet_rate_ms = 300 is shorter than poll_period_ms = 400 "
            "(from [defaults], line 3): the node expects a poll at least once per expected packet "
            "rate\n"
            "t.toml:5:16: no_commander = \"stop\" is not a policy: use \"idle\" or \"hold\"");
}

TEST(ConfigErrors, DuplicateMacOnAPort) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 4\n"
                              "name = \"first\"\n"
                              "[[port.node]]\n"
                              "mac = 4\n"
                              "name = \"second\"\n"),
            "t.toml:10:7: mac = 4 is already used on port \"A\" by node \"first\" (line 7)");
}

TEST(ConfigErrors, SameMacOnTwoPortsIsFine) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 4\n"
                              "name = \"p\"\n"
                              "[[port]]\n"
                              "name = \"B\"\n"
                              "interface = \"simulated\"\n"
                              "bitrate = 500000\n"
                              "[[port.node]]\n"
                              "mac = 4\n"
                              "name = \"p\"\n"),
            "(none)");
}

TEST(ConfigErrors, NodeWithTheMastersMac) {
  // The rack's master MAC, inherited by the port.
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "master_mac = 3\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 3\n"
                     "name = \"p\"\n"),
            "t.toml:8:7: mac = 3 is the master's own MAC on port \"A\" (the rack's master_mac)");
  // The port's own.
  EXPECT_EQ(problems(ONE_PORT "master_mac = 62\n"
                              "[[port.node]]\n"
                              "mac = 62\n"
                              "name = \"p\"\n"),
            "t.toml:8:7: mac = 62 is the master's own MAC on port \"A\" (master_mac, line 6)");
  // A port with its own master MAC frees the rack's for a node.
  EXPECT_EQ(problems(ONE_PORT "master_mac = 62\n"
                              "[[port.node]]\n"
                              "mac = 0\n"
                              "name = \"p\"\n"),
            "(none)");
}

// Warnings are not errors: a file with errors reports only its errors.
TEST(ConfigErrors, DuplicatePortNamesAndInterfaces) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"can0\"\n"
                     "bitrate = 500000\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"can0\"\n"
                     "bitrate = 500000\n"),
            "t.toml:7:8: port name \"A\" is already used by the port at line 3\n"
            "t.toml:8:13: interface \"can0\" is already used by port \"A\"");
}

TEST(ConfigErrors, EmptyNames) {
  EXPECT_EQ(problems("rack = \"\"\n"
                     "[[port]]\n"
                     "name = \"\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"\"\n"),
            "t.toml:1:8: rack must not be empty\n"
            "t.toml:3:8: name must not be empty\n"
            "t.toml:8:8: name must not be empty");
}

// The rack's DDS partition is named after it: no pattern characters.
TEST(ConfigErrors, ARackNameWithAPatternCharacter) {
  for (const char* rack : {"rack-*", "rack?"}) {
    EXPECT_EQ(problems(std::string("rack = \"") + rack +
                       "\"\n[[port]]\nname = \"A\"\ninterface = \"simulated\"\n"
                       "bitrate = 500000\n[[port.node]]\nmac = 1\nname = \"p\"\n"),
              std::string("t.toml:1:8: rack = \"") + rack +
                  "\": a rack name holds no '*', '?' or control character (its DDS partition, "
                  "dnbridge/RACK, would match other racks' as a pattern, or be cut short)");
  }
  EXPECT_EQ(
      problems("rack = \"a\\u0000b\"\n[[port]]\nname = \"A\"\ninterface = \"simulated\"\n"
               "bitrate = 500000\n[[port.node]]\nmac = 1\nname = \"p\"\n"),
      "t.toml:1:8: rack = \"...\": a rack name holds no '*', '?' or control character (its "
      "DDS partition, dnbridge/RACK, would match other racks' as a pattern, or be cut short)");
}

TEST(ConfigErrors, DuplicateNodeNamesOnAPort) {
  EXPECT_EQ(problems(ONE_PORT "[[port.node]]\n"
                              "mac = 1\n"
                              "name = \"p\"\n"
                              "[[port.node]]\n"
                              "mac = 2\n"
                              "name = \"p\"\n"),
            "t.toml:11:8: name \"p\" is already used on port \"A\" (line 8)");
}

TEST(ConfigErrors, MissingRequiredKeys) {
  EXPECT_EQ(problems(""),
            "t.toml:1:1: missing required key 'rack' in the top level\n"
            "t.toml:1:1: no [[port]]: a rack has at least one DeviceNet port");
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[[port]]\n"
                     "interface = \"simulated\"\n"
                     "  [[port.node]]\n"
                     "  profile = \"cdn127\"\n"
                     "  identity = { vendor_id = 59 }\n"),
            "t.toml:2:1: missing required key 'name' in [[port]]\n"
            "t.toml:2:1: missing required key 'bitrate' in [[port]]\n"
            "t.toml:4:3: missing required key 'mac' in [[port.node]]\n"
            "t.toml:4:3: missing required key 'name' in [[port.node]]\n"
            "t.toml:6:14: missing required key 'product_type' in identity\n"
            "t.toml:6:14: missing required key 'product_code' in identity");
}

TEST(ConfigErrors, PortMustBeAnArrayOfTables) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "[port]\n"
                     "name = \"A\"\n"),
            "t.toml:2:1: port must be an array of tables: write [[port]], not [port]");
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "port = []\n"),
            "t.toml:2:8: port is empty: a rack has at least one DeviceNet port");
  EXPECT_EQ(problems(ONE_PORT "node = 3\n"),
            "t.toml:6:8: node must be an array of tables ([[port.node]]), not an integer");
}

TEST(ConfigErrors, UnsupportedChoices) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "log_level = \"verbose\"\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"can0/x\"\n"
                     "bitrate = 500000\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"p\"\n"
                     "profile = \"cdn999\"\n"),
            "t.toml:2:13: log_level = \"verbose\" is not a level: use \"trace\", \"debug\", "
            "\"info\", \"warn\" or \"error\"\n"
            "t.toml:5:13: interface = \"can0/x\" is not a CAN interface name: use \"simulated\" "
            "or a SocketCAN interface such as \"can0\" (at most 15 characters)\n"
            "t.toml:10:11: profile \"cdn999\" is not a profile: use \"cdn127\" (the default) or "
            "\"eds\" (a device described by its EDS file)");
}

TEST(ConfigErrors, RetryBoundsInOrder) {
  EXPECT_EQ(problems(ONE_PORT "allocate_retry_min_ms = 1000\n"
                              "allocate_retry_max_ms = 500\n"
                              "[[port.node]]\nmac = 1\nname = \"p\"\n"),
            "t.toml:7:25: allocate_retry_max_ms is shorter than allocate_retry_min_ms");
}

TEST(ConfigErrors, SeveralErrorsAreReportedTogetherInFileOrder) {
  try {
    parse_config(
        "rack = \"r\"\n"
        "domian = 1\n"
        "[[port]]\n"
        "name = \"A\"\n"
        "interface = \"simulated\"\n"
        "bitrate = 300000\n"
        "[[port.node]]\n"
        "mac = 64\n"
        "name = \"p\"\n"
        "[[port.node]]\n"
        "mac = 0\n"
        "name = \"q\"\n"
        "analog_deadband_volts = -1\n",
        "rack.toml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_THAT(
        e.problems(),
        ElementsAre("rack.toml:2:1: unknown key 'domian' in the top level (did you mean "
                    "'domain'?)",
                    "rack.toml:6:11: bitrate = 300000 is not a DeviceNet bit rate: use "
                    "125000, 250000 or 500000",
                    "rack.toml:8:7: mac = 64 is out of range: a DeviceNet MAC ID is 0..63",
                    "rack.toml:11:7: mac = 0 is the master's own MAC on port \"A\" (the "
                    "rack's master_mac)",
                    "rack.toml:13:25: analog_deadband_volts = -1 is out of range (0..10 V)"));
    EXPECT_EQ(std::string(e.what()), e.problems()[0] + "\n" + e.problems()[1] + "\n" +
                                         e.problems()[2] + "\n" + e.problems()[3] + "\n" +
                                         e.problems()[4]);
  }
}

TEST(ConfigWarnings, PublishFasterThanPollAndEmptyPort) {
  const DaemonConfig c = parse_config(ONE_PORT
                                      "[[port.node]]\n"
                                      "mac = 1\n"
                                      "name = \"p\"\n"
                                      "publish_max_period_ms = 50\n"
                                      "[[port]]\n"
                                      "name = \"B\"\n"
                                      "interface = \"simulated\"\n"
                                      "bitrate = 500000\n",
                                      "t.toml");
  EXPECT_THAT(c.warnings,
              ElementsAre("t.toml:9:25: publish_max_period_ms = 50 is shorter than poll_period_ms "
                          "= 100 (the default): samples in between repeat the last poll",
                          "t.toml:10:1: port \"B\" has no [[port.node]]: its master scans "
                          "nothing"));
}

// ---------------------------------------------------------------------------
// What the master is given.

TEST(ConfigToMaster, TheScanListIsEachNodesPumpConfigInOrder) {
  PortConfig port;
  for (unsigned m : {9u, 4u}) {
    NodeSettings n;
    n.pump.node.mac = mac(m);
    n.pump.node.name = "pump-" + std::to_string(m);
    n.pump.io = kCdn118;
    n.pump.identity =
        devicenet::ExpectedIdentity{.vendor_id = 1, .product_type = 2, .product_code = 3};
    n.pump.node.poll_period = milliseconds(40);
    port.nodes.push_back(n);
  }
  const auto pumps = to_pump_configs(port);
  ASSERT_EQ(pumps.size(), 2u);
  EXPECT_EQ(pumps[0].node.mac, mac(9));
  EXPECT_EQ(pumps[1].node.mac, mac(4));
  EXPECT_EQ(pumps[0].node.name, "pump-9");
  EXPECT_EQ(pumps[0].node.poll_period, milliseconds(40));
  EXPECT_EQ(pumps[0].io, kCdn118);
  EXPECT_EQ(pumps[0].identity, port.nodes[0].pump.identity);
}

TEST(ConfigToMaster, ScannerConfigCarriesThePortsMasterAndTimings) {
  const DaemonConfig c = parse_config(
      "rack = \"r\"\n"
      "master_mac = 5\n"
      "[[port]]\n"
      "name = \"A\"\n"
      "interface = \"can0\"\n"
      "bitrate = 250000\n"
      "master_vendor_id = 777\n"
      "master_serial_number = 123456789\n"
      "allocate_retry_min_ms = 100\n"
      "allocate_retry_max_ms = 1600\n"
      "fault_recheck_ms = 20000\n"
      "poll_response_timeout_ms = 30\n"
      "explicit_response_timeout_ms = 1500\n"
      "max_consecutive_errors = 3\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\n"
      "[[port]]\n"
      "name = \"B\"\n"
      "interface = \"can1\"\n"
      "bitrate = 500000\n"
      "master_mac = 60\n"
      "[[port.node]]\nmac = 1\nname = \"p\"\n",
      "t.toml");
  const devicenet::ScannerConfig a = to_scanner_config(c.ports.at(0), "host-1");
  EXPECT_EQ(a.master_mac, mac(5));
  EXPECT_EQ(a.vendor_id, 777u);
  EXPECT_EQ(a.serial_number, 123456789u);
  EXPECT_EQ(a.allocate_retry_min, milliseconds(100));
  EXPECT_EQ(a.allocate_retry_max, milliseconds(1600));
  EXPECT_EQ(a.fault_recheck, milliseconds(20000));
  EXPECT_EQ(a.poll_response_timeout, milliseconds(30));
  EXPECT_EQ(a.explicit_messaging.response_timeout, milliseconds(1500));
  EXPECT_EQ(a.max_consecutive_errors, 3u);
  EXPECT_EQ(a.duplicate_mac_window, devicenet::ScannerConfig{}.duplicate_mac_window);
  EXPECT_TRUE(a.nodes.empty());

  const devicenet::ScannerConfig b = to_scanner_config(c.ports.at(1), "host-1");
  EXPECT_EQ(b.master_mac, mac(60));
  EXPECT_EQ(b.vendor_id, 0u);  // dnbridge has no vendor ID of its own
  // No serial given: derived from the host and the port, stable, and
  // different for another host and for another port.
  EXPECT_EQ(b.serial_number, derived_master_serial("host-1", "B"));
  EXPECT_EQ(to_scanner_config(c.ports.at(1), "host-1").serial_number, b.serial_number);
  EXPECT_NE(to_scanner_config(c.ports.at(1), "host-2").serial_number, b.serial_number);
  EXPECT_NE(derived_master_serial("host-1", "A"), b.serial_number);
  EXPECT_EQ(b.allocate_retry_min, devicenet::ScannerConfig{}.allocate_retry_min);
}

TEST(ConfigToMaster, ScanListOfTheExampleFileIsWhatTheRackBuilds) {
  const DaemonConfig c = load_config_file(DNBRIDGE_SOURCE_DIR "/deploy/config/rack-example.toml");
  for (const PortConfig& port : c.ports) {
    SCOPED_TRACE(port.name);
    const auto pumps = to_pump_configs(port);
    const devicenet::ScannerConfig scan =
        rack::PumpRack::scanner_config(to_scanner_config(port, "host-1"), pumps);
    EXPECT_EQ(scan.master_mac, port.master.master_mac);
    ASSERT_EQ(scan.nodes.size(), port.nodes.size());
    for (std::size_t i = 0; i < port.nodes.size(); ++i) {
      const NodeSettings& n = port.nodes[i];
      const devicenet::NodeConfig& node = scan.nodes[i];
      SCOPED_TRACE(n.pump.node.name);
      EXPECT_EQ(node.mac, n.pump.node.mac);
      EXPECT_EQ(node.name, n.pump.node.name);
      EXPECT_EQ(node.poll_period, n.pump.node.poll_period);
      EXPECT_EQ(node.expected_packet_rate, n.pump.node.expected_packet_rate);
      const auto format = cdn127::poll_format(n.pump.io);
      ASSERT_TRUE(format.ok());
      EXPECT_EQ(node.profile.consumed_size, format->request.size);
      EXPECT_EQ(node.profile.produced_size, format->response.size);
      const devicenet::ExpectedIdentity cdn127_identity{.vendor_id = cdn127::kVendorId,
                                                        .product_type = cdn127::kProductType,
                                                        .product_code = cdn127::kProductCode};
      EXPECT_EQ(node.profile.identity, n.pump.identity.value_or(cdn127_identity));
    }
  }
  // The custom I/O node polls with its own sizes: 1 output byte, no analog out.
  const auto custom = cdn127::poll_format(c.ports.at(0).nodes.at(2).pump.io);
  ASSERT_TRUE(custom.ok());
  EXPECT_EQ(custom->request.size, 1u);
}

TEST(ConfigToMaster, EmbeddedDefaultBuildsEightPumps) {
  const DaemonConfig c = embedded_default_config();
  const devicenet::ScannerConfig scan = rack::PumpRack::scanner_config(
      to_scanner_config(c.ports.at(0), "host-1"), to_pump_configs(c.ports[0]));
  ASSERT_EQ(scan.nodes.size(), 8u);
  // CDN127 preset: 4 bytes out, 6 in; CDN118: 3 out, 2 in (README).
  EXPECT_EQ(scan.nodes[0].profile.consumed_size, 4u);
  EXPECT_EQ(scan.nodes[0].profile.produced_size, 6u);
  EXPECT_EQ(scan.nodes[7].profile.consumed_size, 3u);
  EXPECT_EQ(scan.nodes[7].profile.produced_size, 2u);
}

}  // namespace
}  // namespace dnbridge::daemon

namespace dnbridge::daemon {
namespace {

TEST(ConfigFile, BusOffRecoveryIsReadAndDefaultsToTheInterface) {
  const auto read = [](const char* line) {
    return parse_config(std::string(ONE_PORT) + line, "t.toml").ports.at(0).bus_off_recovery;
  };
  EXPECT_EQ(read(""), BusOffRecovery::kInterface);
  EXPECT_EQ(read("bus_off_recovery = \"interface\"\n"), BusOffRecovery::kInterface);
  EXPECT_EQ(read("bus_off_recovery = \"restart\"\n"), BusOffRecovery::kRestart);
  EXPECT_EQ(read("bus_off_recovery = \"report\"\n"), BusOffRecovery::kReport);
  EXPECT_THAT(problems(ONE_PORT "bus_off_recovery = \"reboot\"\n"),
              HasSubstr("t.toml:6:20: bus_off_recovery = \"reboot\" is not a policy"));
}

// ---------------------------------------------------------------------------
// [explicit_policy]

TEST(ConfigExplicitPolicy, EverythingIsRefusedUnlessTheFileAllowsIt) {
  EXPECT_EQ(parse_config(ONE_PORT, "t.toml").explicit_policy, rack::ExplicitPolicy{});
  EXPECT_EQ(parse_config(ONE_PORT "[explicit_policy]\n", "t.toml").explicit_policy,
            rack::ExplicitPolicy{});
  // As shipped, the example and the embedded default write every key out, all false.
  const DaemonConfig example =
      load_config_file(DNBRIDGE_SOURCE_DIR "/deploy/config/rack-example.toml");
  EXPECT_EQ(example.explicit_policy, rack::ExplicitPolicy{});
  EXPECT_EQ(embedded_default_config().explicit_policy, rack::ExplicitPolicy{});
  for (std::size_t i = 0; i < rack::kGuardedRequestKinds; ++i) {
    const auto key = std::string(rack::policy_key(static_cast<rack::GuardedRequest>(i)));
    EXPECT_THAT(std::string(embedded_default_config_text()), HasSubstr(key + " = false\n"));
  }
}

TEST(ConfigExplicitPolicy, EachKeyAllowsItsOwnClass) {
  for (std::size_t i = 0; i < rack::kGuardedRequestKinds; ++i) {
    const auto kind = static_cast<rack::GuardedRequest>(i);
    const std::string key(rack::policy_key(kind));
    SCOPED_TRACE(key);
    const DaemonConfig c =
        parse_config("rack = \"r\"\n[explicit_policy]\n" + key +
                         " = true\n"
                         "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n",
                     "t.toml");
    rack::ExplicitPolicy expected;
    expected.allow(kind, true);
    EXPECT_EQ(c.explicit_policy, expected);
  }
  const DaemonConfig some = parse_config(ONE_PORT
                                         "[explicit_policy]\n"
                                         "allow_allocate_release = true\n"
                                         "allow_output_writes = false\n"
                                         "allow_identity_reset = true\n",
                                         "t.toml");
  EXPECT_TRUE(some.explicit_policy.allow_allocate_release);
  EXPECT_FALSE(some.explicit_policy.allow_connection_changes);
  EXPECT_FALSE(some.explicit_policy.allow_output_writes);
  EXPECT_FALSE(some.explicit_policy.allow_managed_attribute_writes);
  EXPECT_TRUE(some.explicit_policy.allow_identity_reset);
}

TEST(ConfigExplicitPolicy, MistakesAreErrorsWithTheirPosition) {
  EXPECT_EQ(problems(ONE_PORT "[explicit_policy]\n"
                              "allow_output_write = true\n"
                              "allow_identity_reset = \"yes\"\n"
                              "allow_everything = true\n"),
            "t.toml:7:1: unknown key 'allow_output_write' in [explicit_policy] (did you mean "
            "'allow_output_writes'?)\n"
            "t.toml:8:24: allow_identity_reset must be true or false, not a string\n"
            "t.toml:9:1: unknown key 'allow_everything' in [explicit_policy]");
  EXPECT_EQ(problems("explicit_policy = true\n" ONE_PORT),
            "t.toml:1:19: explicit_policy must be a table ([explicit_policy]), not a boolean");
}

}  // namespace
}  // namespace dnbridge::daemon

// ---------------------------------------------------------------------------
// The outputs' safe state and the resume policy.

namespace dnbridge::daemon {
namespace {

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

TEST(ConfigFile, MetricsListenIsHostAndPort) {
  EXPECT_FALSE(parse_config(ONE_PORT, "t.toml").metrics_listen);
  EXPECT_EQ(
      parse_config(ONE_PORT "[metrics]\nlisten = \"127.0.0.1:9731\"\n", "t.toml").metrics_listen,
      "127.0.0.1:9731");
  EXPECT_EQ(
      parse_config(ONE_PORT "[metrics]\nlisten = \"localhost:9731\"\n", "t.toml").metrics_listen,
      "localhost:9731");
  EXPECT_EQ(problems(ONE_PORT "[metrics]\nlisten = \"9731\"\n"),
            "t.toml:7:10: listen = \"9731\" is not HOST:PORT (e.g. \"127.0.0.1:9731\"; the port "
            "1..65535)");
  // No IPv6 in the metrics server: refused here rather than failing at start.
  EXPECT_THAT(problems(ONE_PORT "[metrics]\nlisten = \"[::1]:9731\"\n"),
              HasSubstr("the metrics server has no IPv6"));
  EXPECT_THAT(problems(ONE_PORT "[metrics]\nlisten = \"::1:9731\"\n"),
              HasSubstr("the metrics server has no IPv6"));
  EXPECT_THAT(problems(ONE_PORT "[metrics]\nlisten = \"localhost:99999\"\n"),
              HasSubstr("is not HOST:PORT"));
  EXPECT_THAT(problems(ONE_PORT "[metrics]\n"), HasSubstr("listen"));
  EXPECT_THAT(problems(ONE_PORT "[metrics]\nlisten = \"127.0.0.1:9731\"\nport = 1\n"),
              HasSubstr("unknown key 'port' in [metrics]"));
}

TEST(ConfigFile, SimulatedUnconfiguredNodesAreForASimulatedPortAtFreeMacs) {
  const std::string nodes = "[[port.node]]\nmac = 1\nname = \"p\"\n";
  const DaemonConfig c =
      parse_config(ONE_PORT "simulated_unconfigured = [17, 42]\n" + nodes, "t.toml");
  ASSERT_EQ(c.ports.at(0).simulated_unconfigured.size(), 2u);
  EXPECT_EQ(c.ports.at(0).simulated_unconfigured[1], mac(42));
  EXPECT_EQ(problems(ONE_PORT "simulated_unconfigured = [1, 0, 17, 17]\n" + nodes),
            "t.toml:6:27: simulated_unconfigured: MAC 1 is a configured node's\n"
            "t.toml:6:30: simulated_unconfigured: MAC 0 is the master's\n"
            "t.toml:6:37: simulated_unconfigured: MAC 17 is given twice");
  EXPECT_THAT(problems("rack = \"r\"\n[[port]]\nname = \"A\"\ninterface = \"can0\"\n"
                       "bitrate = 500000\nsimulated_unconfigured = [17]\n"),
              HasSubstr("simulated_unconfigured is for a port whose interface is \"simulated\""));
  EXPECT_THAT(problems(ONE_PORT "simulated_unconfigured = 17\n"),
              HasSubstr("simulated_unconfigured must be an array of MAC IDs"));
  EXPECT_THAT(problems(ONE_PORT "simulated_unconfigured = [64]\n"), HasSubstr("64"));
}

}  // namespace
}  // namespace dnbridge::daemon
