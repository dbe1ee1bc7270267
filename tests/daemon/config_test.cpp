// Rack files that load: the shipped example and embedded default, what each
// key gives and where it may be written, the explicit policy, and the scan
// list and scanner settings the master is given.
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
#include "config_text.hpp"

namespace dnbridge::daemon {
namespace {

namespace cdn127 = profiles::cdn127;
using config_test::mac;
using config_test::problems;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

const cdn127::IoConfiguration kCdn127 = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
const cdn127::IoConfiguration kCdn118 = cdn127::preset(cdn127::ConfigurationPreset::kCdn118);

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
