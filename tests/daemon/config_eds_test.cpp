// Nodes described by their EDS files in the configuration (profile = "eds"):
// the file read relative to the configuration, its problems reported at the
// eds key with their own FILE:LINE, the connection, parameters and safe
// state checked against it, and the keys of one profile refused on the other.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "adapters/daemon/config.hpp"
#include "config_text.hpp"

namespace dnbridge::daemon {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// The example I/O block's safe state: its four parameters, on four lines.
#define IO_BLOCK_SAFE_STATE                                        \
  "[ { name = \"Output fault action\", value = 0 },\n"             \
  "               { name = \"Output fault value\", value = 0 },\n" \
  "               { name = \"Output idle action\", value = 0 },\n" \
  "               { name = \"Output idle value\", value = 0 } ]\n"

// Lines 6..: the example I/O block at MAC 20, with its safe state.
#define IO_BLOCK                              \
  "[[port.node]]\n"                           \
  "mac = 20\n"                                \
  "name = \"io-1\"\n"                         \
  "profile = \"eds\"\n"                       \
  "eds = \"dnbridge-example-io-block.eds\"\n" \
  "safe_state_parameters = " IO_BLOCK_SAFE_STATE

DaemonConfig parse(std::string_view text, const std::filesystem::path& base = DNBRIDGE_EDS_DIR) {
  return parse_config(text, "t.toml", base);
}

using config_test::problems;

TEST(ConfigEds, ANodeDescribedByItsEdsLoadsWithItsParametersAndSafeState) {
  const DaemonConfig c = parse(ONE_PORT IO_BLOCK
                               "parameters = [ { name = \"Input filter\", value = 5 } ]\n"
                               "connection = \"poll\"\n"
                               "poll_period_ms = 20\n"
                               "no_commander = \"hold\"\n");
  ASSERT_EQ(c.ports.at(0).nodes.size(), 1u);
  const NodeSettings& n = c.ports[0].nodes[0];
  EXPECT_TRUE(n.is_eds());
  ASSERT_NE(n.eds, nullptr);
  EXPECT_EQ(n.eds->device.product_name, "Example IO block 8DI/8DO/1AI");
  EXPECT_EQ(n.eds_path, std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-io-block.eds");
  EXPECT_NE(n.eds_digest, 0u);
  ASSERT_EQ(n.eds_node.parameters.size(), 1u);
  EXPECT_EQ(n.eds_node.parameters[0], (profiles::eds::ParameterValue{"Input filter", 5}));
  EXPECT_EQ(n.eds_node.safe_state.size(), 4u);

  const rack::PortNodes nodes = to_port_nodes(c.ports[0]);
  EXPECT_TRUE(nodes.of<rack::PumpConfig>().empty());
  ASSERT_EQ(nodes.of<rack::DeviceConfig>().size(), 1u);
  const rack::DeviceConfig& d = nodes.of<rack::DeviceConfig>()[0];
  EXPECT_EQ(d.node.mac.value(), 20);
  EXPECT_EQ(d.node.name, "io-1");
  EXPECT_EQ(d.node.poll_period, milliseconds(20));
  EXPECT_EQ(d.no_commander, rack::NoCommanderPolicy::kHoldLastOutputs);
  EXPECT_EQ(d.eds, n.eds);
  // The master's scan list takes it as the EDS says.
  const auto list = rack::RackPort::scan_list(to_scanner_config(c.ports[0], "host"), nodes);
  ASSERT_EQ(list.nodes.size(), 1u);
  EXPECT_EQ(list.nodes[0].profile.identity, (devicenet::ExpectedIdentity{65001, 7, 1}));
  EXPECT_EQ(list.nodes[0].profile.settings.size(), 5u);
}

TEST(ConfigEds, SafeStateParametersLeftToTheDeviceAreWarnedOf) {
  const DaemonConfig c =
      parse(ONE_PORT
            "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
            "eds = \"dnbridge-example-io-block.eds\"\n"
            "safe_state_parameters = [ { name = \"Output idle action\", value = 0 },\n"
            "               { name = \"Output idle value\", value = 0 } ]\n");
  ASSERT_EQ(c.warnings.size(), 2u);
  EXPECT_THAT(c.warnings[0], HasSubstr("t.toml:10:7: node 20: Param6 \"Output fault action\" is "
                                       "set neither in safe_state_parameters nor in parameters: "
                                       "the device "
                                       "keeps its own value"));
  EXPECT_THAT(c.warnings[1], HasSubstr("Param7 \"Output fault value\""));
  EXPECT_TRUE(parse(ONE_PORT IO_BLOCK).warnings.empty());
}

// A device whose outputs' fault and idle behaviour its maker fixes is
// configured by saying so: read where its EDS names it, never written,
// warned of at every start (the load's warnings are logged).
TEST(ConfigEds, SafeStateDeviceLeavesTheSafeStateToTheDeviceAndIsWarnedOf) {
  const DaemonConfig c = parse(ONE_PORT
                               "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                               "eds = \"dnbridge-example-io-block.eds\"\n"
                               "safe_state = \"device\"\n");
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  EXPECT_TRUE(n.eds_node.safe_state_of_device);
  EXPECT_TRUE(n.eds_node.safe_state.empty());
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0],
              HasSubstr("t.toml:11:14: node 20: its outputs' fault and idle behaviour is the "
                        "device's own (safe_state = \"device\"): read at start-up: Param6 "
                        "\"Output fault action\", Param7 \"Output fault value\", Param8 "
                        "\"Output idle action\", Param9 \"Output idle value\", never written"));
  const auto list =
      rack::RackPort::scan_list(to_scanner_config(c.ports[0], "host"), to_port_nodes(c.ports[0]));
  ASSERT_EQ(list.nodes.size(), 1u);
  ASSERT_EQ(list.nodes[0].profile.settings.size(), 4u);
  for (const auto& setting : list.nodes[0].profile.settings) {
    EXPECT_TRUE(setting.keep_device_value) << setting.name;
  }
  // "configured", as for a CDN127, takes its values from safe_state_parameters.
  EXPECT_THAT(
      problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                        "eds = \"dnbridge-example-io-block.eds\"\nsafe_state = \"configured\"\n"),
      HasSubstr("t.toml:10:7: node 20 (" + std::string(DNBRIDGE_EDS_DIR) +
                "/dnbridge-example-io-block.eds): the node has outputs (output 2 B \"Outputs\" "
                "= Assem150 (Outputs)) and no safe state: give the parameters that set their "
                "fault and idle actions (safe_state_parameters), or safe_state = \"device\" "
                "where the device's maker fixes them"));
  EXPECT_THAT(
      problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                        "eds = \"dnbridge-example-io-block.eds\"\nsafe_state = \"factory\"\n"),
      HasSubstr("t.toml:11:14: safe_state = \"factory\" is not a choice: use \"configured\""));
}

// safe_state = [ ... ] is safe_state_parameters = [ ... ], said in a
// warning; both at once is an error.
TEST(ConfigEds, SafeStateAsAnArrayIsReadAsItsParametersAndWarnedOf) {
  const DaemonConfig c = parse(ONE_PORT
                               "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                               "eds = \"dnbridge-example-io-block.eds\"\n"
                               "safe_state = " IO_BLOCK_SAFE_STATE);
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  EXPECT_EQ(n.eds_node.safe_state.size(), 4u);
  EXPECT_FALSE(n.eds_node.safe_state_of_device);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_EQ(c.warnings[0],
            "t.toml:11:14: safe_state = [ ... ] is read as safe_state = \"configured\" with "
            "safe_state_parameters = [ ... ]: write it so (safe_state says \"configured\" or "
            "\"device\" for every profile)");
  // A node's own array is its own configured safe state, whatever [defaults] says.
  const DaemonConfig d = parse(
      "rack = \"r\"\n[defaults]\nsafe_state = \"device\"\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
      "eds = \"dnbridge-example-io-block.eds\"\n"
      "safe_state = " IO_BLOCK_SAFE_STATE);
  EXPECT_FALSE(d.ports.at(0).nodes.at(0).eds_node.safe_state_of_device);
  EXPECT_EQ(d.ports[0].nodes[0].eds_node.safe_state.size(), 4u);
  // Its parameters alone, under [defaults]' "device", say two things: where
  // "device" comes from is named.
  EXPECT_THAT(
      problems("rack = \"r\"\n[defaults]\nsafe_state = \"device\"\n"
               "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
               "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
               "eds = \"dnbridge-example-io-block.eds\"\n"
               "safe_state_parameters = [ { name = \"Output idle action\", value = 0 } ]\n"),
      HasSubstr("t.toml:13:25: safe_state_parameters has no effect with safe_state = "
                "\"device\" (from [defaults], line 3): the device's own fault and idle "
                "actions are kept"));
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                                "eds = \"dnbridge-example-io-block.eds\"\n"
                                "safe_state = [ { name = \"Output idle action\", value = 0 } ]\n"
                                "safe_state_parameters = [ { name = \"Output idle action\", "
                                "value = 0 } ]\n"),
              HasSubstr("t.toml:12:25: safe_state_parameters and safe_state = [ ... ] both give "
                        "the parameters: keep safe_state_parameters"));
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                                "eds = \"dnbridge-example-io-block.eds\"\n"
                                "safe_state = \"device\"\n"
                                "safe_state_parameters = [ { name = \"Output idle action\", "
                                "value = 0 } ]\n"),
              HasSubstr("t.toml:12:25: safe_state_parameters has no effect with safe_state = "
                        "\"device\": the device's own fault and idle actions are kept"));
}

// [defaults] holds every node key but mac, name and serial; a key of one
// profile there is for the nodes of that profile.
TEST(ConfigEds, DefaultsHoldAnEdsNodesKeysForTheEdsNodes) {
  const DaemonConfig c = parse(
      "rack = \"r\"\n"
      "[defaults]\n"
      "eds = \"dnbridge-example-io-block.eds\"\n"
      "connection = \"change-of-state\"\n"
      "heartbeat_ms = 700\n"
      "parameters = [ { name = \"Input filter\", value = 5 } ]\n"
      "safe_state = \"device\"\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 1\nname = \"pump-1\"\n"
      "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
      "[[port.node]]\nmac = 21\nname = \"io-2\"\nprofile = \"eds\"\nheartbeat_ms = 900\n"
      "safe_state = \"configured\"\n"
      "safe_state_parameters = [ { name = \"Output fault action\", value = 0 },\n"
      "  { name = \"Output fault value\", value = 0 },\n"
      "  { name = \"Output idle action\", value = 0 },\n"
      "  { name = \"Output idle value\", value = 0 } ]\n");
  const auto& nodes = c.ports.at(0).nodes;
  ASSERT_EQ(nodes.size(), 3u);
  // The pump takes the shared safe_state; the EDS keys are not for it.
  EXPECT_FALSE(nodes[0].is_eds());
  EXPECT_EQ(nodes[0].pump.safe_state.source, profiles::cdn127::SafeStateSource::kDevice);
  for (const NodeSettings* n : {&nodes[1], &nodes[2]}) {
    EXPECT_TRUE(n->is_eds());
    ASSERT_NE(n->eds, nullptr);
    EXPECT_EQ(n->eds_node.connection, profiles::eds::ConnectionKind::kChangeOfState);
    ASSERT_EQ(n->eds_node.parameters.size(), 1u);
  }
  EXPECT_EQ(nodes[1].eds_node.heartbeat, milliseconds(700));
  EXPECT_TRUE(nodes[1].eds_node.safe_state_of_device);
  EXPECT_EQ(nodes[2].eds_node.heartbeat, milliseconds(900));
  EXPECT_FALSE(nodes[2].eds_node.safe_state_of_device);
  EXPECT_EQ(nodes[2].eds_node.safe_state.size(), 4u);
  // [defaults]' connection settings are for the nodes whose connection takes
  // them; a node's own that its connection does not take is an error.
  const DaemonConfig mixed = parse(
      "rack = \"r\"\n[defaults]\nprofile = \"eds\"\neds = \"dnbridge-example-io-block.eds\"\n"
      "safe_state = \"device\"\nheartbeat_ms = 700\ninhibit_ms = 800\n"
      "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
      "[[port.node]]\nmac = 20\nname = \"io-1\"\n"
      "[[port.node]]\nmac = 21\nname = \"io-2\"\nconnection = \"change-of-state\"\n"
      "inhibit_ms = 5\n");
  ASSERT_EQ(mixed.ports.at(0).nodes.size(), 2u);
  EXPECT_EQ(mixed.ports[0].nodes[0].eds_node.connection, profiles::eds::ConnectionKind::kPoll);
  EXPECT_EQ(mixed.ports[0].nodes[1].eds_node.heartbeat, milliseconds(700));
  EXPECT_EQ(mixed.ports[0].nodes[1].eds_node.inhibit, milliseconds(5));
  EXPECT_THAT(
      problems("rack = \"r\"\n[defaults]\nheartbeat_ms = 700\n"
               "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
               "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
               "eds = \"dnbridge-example-io-block.eds\"\nsafe_state = \"device\"\n"
               "connection = \"change-of-state\"\ninhibit_ms = 900\n"
               "[[port.node]]\nmac = 21\nname = \"io-2\"\nprofile = \"eds\"\n"
               "eds = \"dnbridge-example-io-block.eds\"\nsafe_state = \"device\"\n"
               "acknowledged = false\n"),
      AllOf(HasSubstr("t.toml:15:14: inhibit_ms = 900 is not shorter than heartbeat_ms = 700 (from "
                      "[defaults], line 3)"),
            HasSubstr("t.toml:22:16: acknowledged is for connection = \"change-of-state\" or "
                      "\"cyclic\" (this node's is \"poll\")")));
  // [defaults]' values are checked even when no node takes them, and its
  // CDN127 keys are for the CDN127s whatever profile it gives the others.
  EXPECT_TRUE(parse("rack = \"r\"\n"
                    "[defaults]\n"
                    "profile = \"eds\"\n"
                    "pump_on_fault = \"off\"\n"
                    "io = \"cdn118\"\n"
                    "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n")
                  .ports.at(0)
                  .nodes.empty());
  EXPECT_THAT(problems("rack = \"r\"\n"
                       "[defaults]\n"
                       "safe_state = \"device\"\n"
                       "safe_state_parameters = 3\n"
                       "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"),
              HasSubstr("t.toml:4:25: safe_state_parameters must be an array"));
  EXPECT_THAT(problems("rack = \"r\"\n"
                       "[defaults]\n"
                       "heartbeat_ms = 0\n"
                       "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"),
              HasSubstr("t.toml:3:16: heartbeat_ms = 0 is out of range (1..65535 ms)"));
}

TEST(ConfigEds, TheShippedExampleLoads) {
  const DaemonConfig c =
      load_config_file(std::string(DNBRIDGE_SOURCE_DIR) + "/deploy/config/eds-rack-example.toml");
  EXPECT_TRUE(c.warnings.empty());
  const rack::PortNodes nodes = to_port_nodes(c.ports.at(0));
  ASSERT_EQ(nodes.of<rack::PumpConfig>().size(), 1u);
  ASSERT_EQ(nodes.of<rack::DeviceConfig>().size(), 3u);
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[0].eds->device.product_name,
            "Example IO block 8DI/8DO/1AI");
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[0].settings.connection,
            profiles::eds::ConnectionKind::kPoll);
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[1].settings.connection,
            profiles::eds::ConnectionKind::kChangeOfState);
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[1].settings.heartbeat, milliseconds(500));
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[2].eds->device.product_name,
            "Example valve manifold 16");
  EXPECT_EQ(nodes.of<rack::DeviceConfig>()[2].settings.connection,
            profiles::eds::ConnectionKind::kStrobe);
}

TEST(ConfigEds, APumpAndADeviceShareAPort) {
  const DaemonConfig c = parse(ONE_PORT "[[port.node]]\nmac = 1\nname = \"pump-1\"\n" IO_BLOCK);
  const rack::PortNodes nodes = to_port_nodes(c.ports.at(0));
  ASSERT_EQ(nodes.of<rack::PumpConfig>().size(), 1u);
  ASSERT_EQ(nodes.of<rack::DeviceConfig>().size(), 1u);
  EXPECT_EQ(to_pump_configs(c.ports[0]).size(), 1u);
}

TEST(ConfigEds, ARelativePathIsTheConfigurationFilesNeighbour) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "config_eds_relative";
  std::filesystem::create_directories(dir / "eds");
  std::filesystem::copy_file(std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-io-block.eds",
                             dir / "eds" / "block.eds",
                             std::filesystem::copy_options::overwrite_existing);
  {
    std::ofstream f(dir / "rack.toml");
    f << ONE_PORT
        "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\neds = \"eds/block.eds\"\n"
        "safe_state_parameters = [ { name = \"Output idle action\", value = 0 } ]\n";
  }
  const DaemonConfig c = load_config_file(dir / "rack.toml");
  ASSERT_NE(c.ports.at(0).nodes.at(0).eds, nullptr);
  EXPECT_EQ(c.ports[0].nodes[0].eds_path, (dir / "eds" / "block.eds").string());
}

TEST(ConfigEds, AnEdsFilesProblemsAreReportedAtTheKeyWithTheirOwnLines) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "config_eds_bad";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "bad.eds");
    f << "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
         "[IO_Info]\nPollInfo = 1, 3, 0;\n";
  }
  const std::string text = ONE_PORT
      "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\neds = \"bad.eds\"\n"
      "[[port.node]]\nmac = 21\nname = \"io-2\"\nprofile = \"eds\"\neds = \"bad.eds\"\n";
  const std::string p = problems(text, dir);
  const std::string bad = (dir / "bad.eds").string();
  EXPECT_THAT(p, HasSubstr("t.toml:10:7: eds: " + bad +
                           ":4: error: poll connection: Input3 is not in [IO_Info]"));
  // Read once: the second node says where its problems are.
  EXPECT_THAT(p, HasSubstr("t.toml:15:7: eds = \"" + bad +
                           "\" is not usable (its problems are listed at line 10)"));
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                                "eds = \"no-such.eds\"\n"),
              HasSubstr("t.toml:10:7: eds: " + std::string(DNBRIDGE_EDS_DIR) +
                        "/no-such.eds: cannot open: No such file or directory"));
  // One [defaults]' eds for every node: its problems said once, at it.
  EXPECT_EQ(problems("rack = \"r\"\n[defaults]\neds = \"no-such.eds\"\n"
                     "[[port]]\nname = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n"
                     "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                     "[[port.node]]\nmac = 21\nname = \"io-2\"\nprofile = \"eds\"\n"),
            "t.toml:3:7: eds: " + std::string(DNBRIDGE_EDS_DIR) +
                "/no-such.eds: cannot open: No such file or directory");
}

TEST(ConfigEds, WhatTheMasterWouldRefuseIsAnErrorAtItsKey) {
  // Outputs without a safe state.
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 20\nname = \"io-1\"\nprofile = \"eds\"\n"
                                "eds = \"dnbridge-example-io-block.eds\"\n"),
              HasSubstr("t.toml:10:7: node 20 (" + std::string(DNBRIDGE_EDS_DIR) +
                        "/dnbridge-example-io-block.eds): the node has outputs"));
  // A parameter that is not in the EDS, at the parameters key.
  EXPECT_THAT(
      problems(ONE_PORT IO_BLOCK "parameters = [ { name = \"Input filtr\", value = 5 } ]\n"),
      HasSubstr("t.toml:15:14: node 20 (" + std::string(DNBRIDGE_EDS_DIR) +
                "/dnbridge-example-io-block.eds): parameters: the EDS has no parameter "
                "\"Input filtr\" (did you mean \"Input filter\"?)"));
  // A connection the EDS does not offer, at the connection key.
  EXPECT_THAT(
      problems(ONE_PORT IO_BLOCK "connection = \"bit-strobe\"\n"),
      HasSubstr("t.toml:15:14: node 20 (" + std::string(DNBRIDGE_EDS_DIR) +
                "/dnbridge-example-io-block.eds): the EDS offers no bit-strobe connection"));
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "connection = \"strobe\"\n"),
              HasSubstr("t.toml:15:14: connection = \"strobe\" is not a connection"));
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "parameters = [ { name = \"Input filter\" } ]\n"),
              HasSubstr("t.toml:15:16: missing required key 'value' in parameters"));
}

TEST(ConfigEds, AChangeOfStateNodeTakesItsHeartbeatInhibitAndAcknowledgment) {
  const DaemonConfig c = parse(ONE_PORT IO_BLOCK
                               "connection = \"change-of-state\"\n"
                               "heartbeat_ms = 250\n"
                               "inhibit_ms = 15\n"
                               "acknowledged = false\n");
  const NodeSettings& n = c.ports.at(0).nodes.at(0);
  EXPECT_EQ(n.eds_node.connection, profiles::eds::ConnectionKind::kChangeOfState);
  EXPECT_EQ(n.eds_node.heartbeat, milliseconds(250));
  EXPECT_EQ(n.eds_node.inhibit, milliseconds(15));
  EXPECT_FALSE(n.eds_node.acknowledged);
  const auto nodes = to_port_nodes(c.ports[0]);
  const auto list = rack::RackPort::scan_list(to_scanner_config(c.ports[0], "host"), nodes);
  ASSERT_TRUE(list.nodes.at(0).profile.input_connection.has_value());
  EXPECT_EQ(list.nodes[0].profile.input_connection->expected_packet_rate, milliseconds(250));

  // Only for the connections they are about.
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "heartbeat_ms = 250\n"),
              HasSubstr("t.toml:15:16: heartbeat_ms is for connection = \"change-of-state\" or "
                        "\"cyclic\" (this node's is \"poll\")"));
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "connection = \"cyclic\"\ninhibit_ms = 5\n"),
              HasSubstr("t.toml:16:14: inhibit_ms is for connection = \"change-of-state\""));
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "connection = \"cyclic\"\nheartbeat_ms = 0\n"),
              HasSubstr("t.toml:16:16: heartbeat_ms"));
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 1\nname = \"p\"\nacknowledged = true\n"),
              HasSubstr("t.toml:9:16: acknowledged is for profile = \"eds\" nodes"));
}

TEST(ConfigEds, TheKeysOfOneProfileAreRefusedOnTheOther) {
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "io = \"cdn127\"\npump_on_fault = \"off\"\n"),
              HasSubstr("t.toml:15:6: io is a CDN127 setting: this node has profile = \"eds\""));
  EXPECT_THAT(problems(ONE_PORT IO_BLOCK "io = \"cdn127\"\npump_on_fault = \"off\"\n"),
              HasSubstr("t.toml:16:17: pump_on_fault is a CDN127 setting"));
  EXPECT_THAT(problems(ONE_PORT "[[port.node]]\nmac = 1\nname = \"p\"\neds = \"x.eds\"\n"),
              HasSubstr("t.toml:9:7: eds is for profile = \"eds\" nodes"));
  EXPECT_THAT(
      problems(ONE_PORT "[[port.node]]\nmac = 1\nname = \"p\"\nprofile = \"edz\"\n"),
      HasSubstr("profile \"edz\" is not a profile: use \"cdn127\" (the default) or \"eds\""));
  // [defaults] may hold CDN127 settings: they are for the CDN127s.
  EXPECT_EQ(problems(ONE_PORT "[defaults]\npump_on_fault = \"off\"\nio = \"cdn118\"\n" IO_BLOCK),
            "(none)");
}

}  // namespace
}  // namespace dnbridge::daemon
