// Rack files refused or warned of: each problem with its position and text,
// several together in file order.
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
using ::testing::Not;

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

}  // namespace
}  // namespace dnbridge::daemon
