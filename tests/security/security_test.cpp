// DDS Security end to end, with the PKI the shipped script made at test
// time (make_test_pki.sh, ctest fixture security_pki): the bridge of the
// simulated rack runs in this process with the bridge identity of the site;
// every other identity is a process of its own (dnbctl, or
// dnbridge_security_probe), because participants of one process share
// Cyclone's domain and reach each other without DDS Security's checks.
// Every node's no-commander policy is "hold": whatever a command did to a
// pump stays on the simulated device after its commander has gone, so
// checking the device's outputs afterwards sees any command that got
// through, however briefly.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/simulated_backends.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/security/check.hpp"
#include "adapters/security/toml_settings.hpp"
#include "bridge/profiles/cdn127/io_data.hpp"
#include "dnbctl/subprocess.hpp"
#include "e2e/bridge_fixture.hpp"
#include "support/simulated_rack.hpp"

namespace dnbridge::security_test {
namespace {

namespace fs = std::filesystem;
using dnbctl::testing::run;
using dnbctl::testing::RunResult;
using e2e::CapturingLog;
using profiles::cdn127::PumpOutputs;

constexpr dds_domainid_t kDomain = DNBRIDGE_SECURITY_TEST_DOMAIN;  // the PKI's

const fs::path kPki = DNBRIDGE_SECURITY_TEST_PKI;
fs::path host(const std::string& name) { return kPki / "site" / "hosts" / name; }
fs::path security_file(const std::string& name) { return host(name) / "security.toml"; }

// The settings the script wrote for `name` (its security.toml).
security::Settings settings_of(const std::string& name) {
  return security::load_file(security_file(name));
}

// The [security] table of `s`, as a rack configuration holds it.
std::string security_table(const security::Settings& s) {
  std::ostringstream t;
  t << "\n[security]\n"
    << "identity_ca = " << s.identity_ca << "\ncertificate = " << s.certificate
    << "\nprivate_key = " << s.private_key << "\npermissions_ca = " << s.permissions_ca
    << "\ngovernance = " << s.governance << "\npermissions = " << s.permissions << "\n";
  return t.str();
}

// `dnbridge-sim --simulate`'s rack on the PKI's domain, as a file, with `security`.
fs::path write_rack_config(const std::string& name, const std::string& security,
                           int domain = kDomain) {
  const std::string text = support::simulated_rack_config(domain);
  const auto path = fs::temp_directory_path() /
                    ("dnbridge-security-" + std::to_string(getpid()) + "-" + name + ".toml");
  std::ofstream(path) << text << security;
  return path;
}

// One line of a program's output, "key: value"; empty when absent.
std::string field(const std::string& out, const std::string& key) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(key + ": ", 0) == 0) return line.substr(key.size() + 2);
  }
  return {};
}
long number(const std::string& out, const std::string& key) {
  const auto v = field(out, key);
  return v.empty() ? -2 : std::stol(v);
}

std::size_t lines(const std::string& text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

RunResult dnbctl(const std::vector<std::string>& args) { return run(DNBCTL_PATH, args); }

// The probe as `identity` (empty: no credentials), with `options`; killed
// if it outlives `timeout`.
RunResult probe(const std::string& identity, std::vector<std::string> options,
                std::chrono::seconds timeout = std::chrono::seconds(30)) {
  std::vector<std::string> args{"--domain", std::to_string(kDomain)};
  if (!identity.empty()) {
    args.push_back("--security");
    args.push_back(security_file(identity).string());
  }
  args.insert(args.end(), options.begin(), options.end());
  return run(DNBRIDGE_SECURITY_PROBE, args, timeout);
}

// The probe for `seconds`, as `identity`, commanding `mac` if not 0.
RunResult probe(const std::string& identity, double seconds, unsigned mac = 0) {
  std::vector<std::string> options{"--seconds", std::to_string(seconds)};
  if (mac != 0) {
    options.push_back("--command");
    options.push_back(std::to_string(mac));
  }
  return probe(identity, options);
}

::testing::AssertionResult ran(const RunResult& r, int expected_exit) {
  if (r.exit_code == expected_exit) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "exit " << r.exit_code << " (expected " << expected_exit << ")\nstdout:\n"
         << r.out << "stderr:\n"
         << r.err;
}

// --- the bridge in this process ----------------------------------------------------

class SecureBridgeTest : public ::testing::Test {
 protected:
  // The simulated rack with the bridge identity of the site, every node
  // holding its outputs when no commander is left.
  static daemon::DaemonConfig rack_config() {
    auto c = daemon::embedded_default_config();
    c.domain_id = kDomain;
    for (auto& port : c.ports) {
      for (auto& node : port.nodes)
        node.pump.no_commander = daemon::NoCommanderPolicy::kHoldLastOutputs;
    }
    c.security = settings_of("rack");
    return c;
  }

  void TearDown() override {
    if (HasFailure()) {
      std::fprintf(stderr, "bridge log:\n");
      log_.dump();
    }
  }

  // Started, and every node online as the port reports it (checked every
  // 20 ms, at most 10 s).
  void start_online(daemon::DaemonConfig config = rack_config()) {
    bridge_ = std::make_unique<daemon::Daemon>(std::move(config), log_,
                                               daemon::simulated_backend_factory(log_));
    bridge_->start();
    auto* port = bridge_->port(e2e::kPort);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (port->nodes_online() != port->nodes_configured()) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the nodes did not come online";
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  // What the simulated CDN127 at `mac` drives on its outputs now.
  PumpOutputs device_outputs(unsigned mac) {
    return e2e::on_sim_port(*bridge_, e2e::kPort, [mac](sim::SimBackend& b) {
      return b.device(*devicenet::MacId::from(mac)).device().outputs();
    });
  }

  CapturingLog log_;
  std::unique_ptr<daemon::Daemon> bridge_;
};

// dnbctl list, with the same timeout: with the monitor's credentials it
// finds the bridge, so that without any credentials finding none means
// something (the timeout is ample for discovery, and for DDS Security's
// handshakes, on a loaded machine).
void expect_only_credentials_find_the_bridge() {
  const std::vector<std::string> list{"--domain", std::to_string(kDomain), "--timeout", "5",
                                      "list"};
  std::vector<std::string> with_credentials{"--security", security_file("ops").string()};
  with_credentials.insert(with_credentials.end(), list.begin(), list.end());
  const auto control = dnbctl(with_credentials);
  EXPECT_TRUE(ran(control, 0)) << "with the monitor's credentials";
  EXPECT_NE(control.out.find("8/8 online"), std::string::npos) << control.out;
  const auto without = dnbctl(list);
  EXPECT_TRUE(ran(without, 3)) << "without credentials";
}

// What the probe's command sets, and a pump nobody commanded.
const PumpOutputs kProbeCommand{true, true, 1234};
const PumpOutputs kUntouched{};

// (a) A supervisor with valid credentials commands a pump: dnbctl as the
// operator runs it, and the probe writing blind as any program would; the
// simulated devices' outputs change.
TEST_F(SecureBridgeTest, SupervisorWithValidCredentialsCommandsThePump) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  ASSERT_EQ(device_outputs(3), kUntouched);
  const auto r = dnbctl({"--domain", std::to_string(kDomain), "--security",
                         security_file("scada").string(), "--timeout", "10", "pump", "3", "on"});
  ASSERT_TRUE(ran(r, 0));
  EXPECT_NE(r.out.find("applied: pump on"), std::string::npos) << r.out;
  EXPECT_TRUE(device_outputs(3).pump_on);

  ASSERT_EQ(device_outputs(4), kUntouched);
  const auto p = probe("scada", 2.0, 4);
  ASSERT_TRUE(ran(p, 0));
  EXPECT_EQ(field(p.out, "command_writer"), "created") << p.out;
  EXPECT_GE(number(p.out, "command_readers_matched"), 1) << p.out;
  EXPECT_GT(number(p.out, "pumpstate_samples"), 0) << p.out;
  EXPECT_EQ(device_outputs(4), kProbeCommand);
}

// (b) Without credentials: nothing seen, nothing moved. The probe without
// credentials and one with the monitor's credentials start together; the
// first commands pump 5 every 100 ms for as long as it runs. The monitor
// runs until it has seen a pump online, waiting at most kAuthorizedWait
// (DDS Security's handshakes take their time on a loaded machine): from
// then on the bridge is known to be publishing to readers it accepts. Only
// then is the start file made, and the probe without credentials runs
// kRogueWindow more after it sees the file. It must have seen nothing, and
// matched no reader, over its whole run, which thus covers at least
// kRogueWindow (its own window_ms, checked) after the monitor had data. No
// bound on how soon the monitor sees data: a slow handshake only makes the
// run longer. (Run by hand against a bridge without DDS Security, the same
// probe saw its first PumpState after 22 ms and matched the bridge's
// PumpCommand reader.)
TEST_F(SecureBridgeTest, ParticipantWithoutCredentialsSeesNothingAndMovesNothing) {
  constexpr auto kAuthorizedWait = std::chrono::seconds(30);
  constexpr auto kRogueWindow = std::chrono::seconds(3);
  ASSERT_NO_FATAL_FAILURE(start_online());
  const auto start_file = fs::temp_directory_path() /
                          ("dnbridge-security-" + std::to_string(getpid()) + "-window-start");
  fs::remove(start_file);
  auto rogue_run = std::async(std::launch::async, [&] {
    return probe("",
                 {"--command", "5", "--start-file", start_file.string(), "--seconds",
                  std::to_string(kRogueWindow.count())},
                 kAuthorizedWait + kRogueWindow + std::chrono::seconds(30));
  });
  const auto monitor =
      probe("ops", {"--until-online", "--seconds", std::to_string(kAuthorizedWait.count())},
            kAuthorizedWait + std::chrono::seconds(10));
  // Made whatever the monitor saw: the probe without credentials ends
  // kRogueWindow later in any case.
  std::ofstream(start_file).put('\n');
  const auto rogue = rogue_run.get();
  fs::remove(start_file);

  ASSERT_TRUE(ran(monitor, 0));
  const long first = number(monitor.out, "first_online_ms");
  e2e::report("monitor: start -> first PumpState of a pump online", static_cast<double>(first));
  ASSERT_GE(first, 0) << "the monitor saw no pump online within " << kAuthorizedWait.count()
                      << " s\n"
                      << monitor.out;

  ASSERT_TRUE(ran(rogue, 0));
  EXPECT_EQ(field(rogue.out, "participant"), "created") << rogue.out;
  EXPECT_EQ(field(rogue.out, "command_writer"), "created") << rogue.out;
  EXPECT_GE(number(rogue.out, "window_ms"),
            std::chrono::duration_cast<std::chrono::milliseconds>(kRogueWindow).count())
      << rogue.out;
  EXPECT_GE(number(rogue.out, "commands_written"), 20) << rogue.out;
  EXPECT_EQ(number(rogue.out, "pumpstate_samples"), 0) << rogue.out;
  EXPECT_EQ(number(rogue.out, "command_readers_matched"), 0) << rogue.out;
  EXPECT_EQ(device_outputs(5), kUntouched);

  expect_only_credentials_find_the_bridge();
}

// (c) The monitor's credentials read PumpState, and writing PumpCommand is
// refused on its own side: Cyclone's access control refuses the topic
// itself (the monitor's grant names no PumpCommand at all), before any
// writer exists. Neither the probe nor dnbctl moves the pump.
TEST_F(SecureBridgeTest, MonitorReadsStateAndIsRefusedPumpCommand) {
  ASSERT_NO_FATAL_FAILURE(start_online());
  const auto p = probe("ops", 2.0, 6);
  ASSERT_TRUE(ran(p, 0));
  EXPECT_EQ(field(p.out, "state_reader"), "created") << p.out;
  EXPECT_GT(number(p.out, "pumpstate_samples"), 0) << p.out;
  const auto refusal = field(p.out, "command_writer");
  EXPECT_EQ(refusal.rfind("refused: creating topic \"dnbridge/PumpCommand\"", 0), 0u) << p.out;
  EXPECT_NE(refusal.find("Not Allowed By Security"), std::string::npos) << p.out;
  EXPECT_EQ(number(p.out, "commands_written"), 0) << p.out;

  const auto list = dnbctl({"--domain", std::to_string(kDomain), "--security",
                            security_file("ops").string(), "--timeout", "10", "list"});
  ASSERT_TRUE(ran(list, 0));
  EXPECT_NE(list.out.find("8/8 online"), std::string::npos) << list.out;
  const auto command =
      dnbctl({"--domain", std::to_string(kDomain), "--security", security_file("ops").string(),
              "--timeout", "10", "pump", "6", "on"});
  ASSERT_TRUE(ran(command, 1));
  EXPECT_NE(command.err.find("Not Allowed By Security"), std::string::npos) << command.err;
  EXPECT_EQ(device_outputs(6), kUntouched);
}

// A host added to the site later needs files on that host only: the bridge
// keeps the permissions document it had, which has no grant for the new
// host (each participant shows the others its own permissions, signed by
// the permissions CA), and serves it.
TEST_F(SecureBridgeTest, AHostAddedLaterNeedsNoNewFilesOnTheBridge) {
  auto config = rack_config();
  config.security = security::load_file(kPki / "rack-before-late" / "security.toml");
  std::ifstream before(config.security->permissions);
  const std::string permissions{std::istreambuf_iterator<char>(before), {}};
  ASSERT_NE(permissions.find("CN=ops,OU=monitor"), std::string::npos);
  ASSERT_EQ(permissions.find("CN=late"), std::string::npos);
  ASSERT_NO_FATAL_FAILURE(start_online(std::move(config)));
  const auto p = probe("late", 2.0);
  ASSERT_TRUE(ran(p, 0));
  EXPECT_GE(number(p.out, "first_online_ms"), 0) << p.out;
}

// A site's permissions signed before the bus scan and reload came: the
// bridge starts all the same, says what it does not offer and why, and
// serves its pumps; dnbctl reload then finds no bridge taking reloads.
TEST_F(SecureBridgeTest, PermissionsSignedBeforeTheServicesCameStillRunTheBridge) {
  auto config = rack_config();
  config.security = security::load_file(kPki / "rack-before-services" / "security.toml");
  std::ifstream before(config.security->permissions);
  const std::string permissions{std::istreambuf_iterator<char>(before), {}};
  ASSERT_NE(permissions.find("dnbridge/PumpCommand"), std::string::npos);
  ASSERT_EQ(permissions.find("dnbridge/Reload"), std::string::npos);
  ASSERT_EQ(permissions.find("dnbridge/BusScan"), std::string::npos);
  ASSERT_NO_FATAL_FAILURE(start_online(std::move(config)));
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "the bus scan (dnbridge/BusScanRequest"));
  EXPECT_TRUE(log_.contains(LogLevel::kWarn, "reload over DDS (dnbridge/ReloadRequest"));
  const auto p = probe("scada", 2.0, 3);
  ASSERT_TRUE(ran(p, 0));
  EXPECT_EQ(device_outputs(3), kProbeCommand);
  const auto reload =
      dnbctl({"--domain", std::to_string(kDomain), "--security", security_file("scada").string(),
              "--rack", e2e::kRack, "--timeout", "5", "reload"});
  EXPECT_TRUE(ran(reload, 3));
  EXPECT_NE(reload.err.find("takes reload requests"), std::string::npos) << reload.err;
}

// The Cyclone XML route: no [security] in the rack configuration, the
// domain's configuration has a <Security> section with the bridge's files
// (as CYCLONEDDS_URI would give it); the supervisor's commands work, a
// participant without credentials finds nothing.
TEST_F(SecureBridgeTest, SecurityFromCycloneXmlConfiguration) {
  const auto s = settings_of("rack");
  const auto library = [&](const char* plugin, const char* init, const char* fini) {
    return "<Library path=\"" + security::plugin_library(s, plugin).string() +
           "\" initFunction=\"" + init + "\" finalizeFunction=\"" + fini + "\"/>";
  };
  const std::string section = "<Security><Authentication>" +
                              library("auth", "init_authentication", "finalize_authentication") +
                              "<IdentityCA>file:" + s.identity_ca.string() +
                              "</IdentityCA><IdentityCertificate>file:" + s.certificate.string() +
                              "</IdentityCertificate><PrivateKey>file:" + s.private_key.string() +
                              "</PrivateKey></Authentication><Cryptographic>" +
                              library("crypto", "init_crypto", "finalize_crypto") +
                              "</Cryptographic><AccessControl>" +
                              library("ac", "init_access_control", "finalize_access_control") +
                              "<PermissionsCA>file:" + s.permissions_ca.string() +
                              "</PermissionsCA><Governance>file:" + s.governance.string() +
                              "</Governance><Permissions>file:" + s.permissions.string() +
                              "</Permissions></AccessControl></Security>";
  // This process's loopback configuration and discovery tag (the children
  // inherit them through CYCLONEDDS_URI), with the section.
  std::string xml = dds::loopback_config("dnbridge-test-" + std::to_string(getpid()));
  xml.insert(xml.find("</Domain>"), section);
  dds::Entity domain(dds_create_domain(kDomain, xml.c_str()));
  ASSERT_GT(domain.handle(), 0) << dds_strretcode(domain.handle());

  auto config = rack_config();
  config.security.reset();
  ASSERT_NO_FATAL_FAILURE(start_online(std::move(config)));
  expect_only_credentials_find_the_bridge();
  const auto r = dnbctl({"--domain", std::to_string(kDomain), "--security",
                         security_file("scada").string(), "--timeout", "10", "pump", "7", "on"});
  ASSERT_TRUE(ran(r, 0));
  EXPECT_TRUE(device_outputs(7).pump_on);
  bridge_.reset();  // its participant before the domain
}

// --- bridges that must not start -------------------------------------------------

// dnbridge, run as a program on a configuration whose [security] table is
// `settings`, and its --check-config: both refuse with one line that names
// `file` and says `reason`, exit code 2, and no bridge ran.
void expect_refused(const std::string& name, const security::Settings& settings,
                    const fs::path& file, const std::string& reason) {
  const auto config = write_rack_config(name, security_table(settings));
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--config", config.string()},
        std::vector<std::string>{"--check-config", config.string()}}) {
    SCOPED_TRACE(args[0]);
    const auto r = run(DNBRIDGE_BINARY, args);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind(file.string() + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("OK"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("running"), std::string::npos) << r.err;
  }
  fs::remove(config);
}

// (d) An expired certificate (issued with openssl ca -startdate/-enddate
// for 2020), and one signed by another site's CA.
TEST(BridgeRefusesToStart, WithAnExpiredCertificate) {
  auto s = settings_of("rack");
  s.certificate = kPki / "expired" / "cert.pem";
  s.private_key = kPki / "expired" / "key.pem";
  expect_refused("expired", s, s.certificate,
                 "identity certificate expired on 2021-01-01 00:00:00 UTC");
}

TEST(BridgeRefusesToStart, WithACertificateOfAnotherCa) {
  auto s = settings_of("rack");
  s.certificate = kPki / "other" / "hosts" / "rack" / "cert.pem";
  s.private_key = kPki / "other" / "hosts" / "rack" / "key.pem";
  expect_refused("other-ca", s, s.certificate,
                 "identity certificate is not signed by the identity CA " + s.identity_ca.string());
}

// The identity CA vouches for itself and for the CAs it issued (openssl
// verify says OK to both); neither is a participant's identity.
TEST(BridgeRefusesToStart, WithTheIdentityCaAsItsCertificate) {
  auto s = settings_of("rack");
  s.certificate = s.identity_ca;
  expect_refused("identity-ca", s, s.certificate,
                 "identity certificate is a CA certificate, not a participant's identity (it is "
                 "the identity CA itself)");
}

TEST(BridgeRefusesToStart, WithACaCertificateIssuedByTheIdentityCa) {
  auto s = settings_of("rack");
  s.certificate = kPki / "sub-ca" / "cert.pem";
  s.private_key = kPki / "sub-ca" / "key.pem";
  ASSERT_EQ(
      run("/usr/bin/openssl", {"verify", "-CAfile", s.identity_ca.string(), s.certificate.string()})
          .exit_code,
      0);
  expect_refused("sub-ca", s, s.certificate,
                 "identity certificate is a CA certificate, not a participant's identity");
}

TEST(BridgeRefusesToStart, WithAGovernanceSignedByAnotherPermissionsCa) {
  auto s = settings_of("rack");
  s.governance = kPki / "other" / "governance.p7s";
  expect_refused("other-governance", s, s.governance,
                 "governance document signature does not verify with the permissions CA");
}

TEST(BridgeRefusesToStart, WithAMissingFile) {
  auto s = settings_of("rack");
  s.permissions = host("rack") / "no-such-permissions.p7s";
  expect_refused("missing", s, s.permissions, "cannot open: No such file or directory");
}

// What Cyclone DDS refuses when the files are in order: its reason, in the
// one line of the failure (after Cyclone's own log line), exit code 1.
TEST(BridgeRefusesToStart, WhenCycloneRefusesTheParticipant) {
  // The documents are for kDomain only.
  const auto config = write_rack_config("domain", security_table(settings_of("rack")), kDomain + 1);
  const auto r = run(DNBRIDGE_BINARY, {"--config", config.string()});
  fs::remove(config);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("error dnbridge: creating the participant of domain " +
                       std::to_string(kDomain + 1) +
                       ": refused by Cyclone DDS: It is not allowed "
                       "to create participant: Could not find domain " +
                       std::to_string(kDomain + 1) + " in governance"),
            std::string::npos)
      << r.err;
}

// --check-config says who the bridge will be on DDS, and so does the log of
// a bridge that starts (the next test's, before Cyclone refuses it).
TEST(BridgeChecksItsConfiguration, AndSaysWhoItWillBe) {
  const auto config = write_rack_config("check", security_table(settings_of("rack")));
  const auto r = run(DNBRIDGE_BINARY, {"--check-config", config.string()});
  fs::remove(config);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind(config.string() + ": rack sim-rack, 1 port(s), 8 node(s), DDS Security as "
                                          "CN=rack,OU=bridge,O=test-site (certificate valid until ",
                        0),
            0u)
      << r.out;
  EXPECT_NE(r.out.find(" UTC): OK\n"), std::string::npos) << r.out;
}

TEST(BridgeRefusesToStart, WithMonitorCredentials) {
  auto config = write_rack_config("monitor", security_table(settings_of("ops")));
  const auto r = run(DNBRIDGE_BINARY, {"--config", config.string()});
  fs::remove(config);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("dnbridge: DDS Security as CN=ops,OU=monitor,O=test-site (certificate "
                       "valid until "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("Not Allowed By Security (-13): DDS Security, the permissions of this "
                       "participant's identity do not allow it"),
            std::string::npos)
      << r.err;
}

TEST(DnbctlRefusesToStart, WithAWrongSecurityFile) {
  // An expired identity, through a security file of its own.
  const auto dir = fs::temp_directory_path() / ("dnbctl-security-" + std::to_string(getpid()));
  fs::create_directories(dir);
  auto s = settings_of("scada");
  s.certificate = kPki / "expired" / "cert.pem";
  s.private_key = kPki / "expired" / "key.pem";
  std::ofstream(dir / "security.toml") << security_table(s);
  const auto r = dnbctl({"--domain", std::to_string(kDomain), "--security",
                         (dir / "security.toml").string(), "list"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "dnbctl: " + s.certificate.string() +
                       ": identity certificate expired on 2021-01-01 00:00:00 UTC\n");
  // A file without [security], and a misspelt key.
  std::ofstream(dir / "empty.toml") << "# nothing\n";
  const auto empty = dnbctl({"--security", (dir / "empty.toml").string(), "list"});
  EXPECT_EQ(empty.exit_code, 2);
  EXPECT_NE(empty.err.find("has no [security] table"), std::string::npos) << empty.err;
  std::ofstream(dir / "typo.toml")
      << "[security]\nidentity_ca = \"a.pem\"\ncertficate = \"c.pem\"\n";
  const auto typo = dnbctl({"--security", (dir / "typo.toml").string(), "list"});
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.err.find("typo.toml:3:1: unknown key 'certficate' in [security] (did you mean "
                          "'certificate'?)"),
            std::string::npos)
      << typo.err;
  // DNBCTL_SECURITY is the default of --security.
  const auto env = run("/usr/bin/env", {"DNBCTL_SECURITY=" + (dir / "security.toml").string(),
                                        DNBCTL_PATH, "--domain", std::to_string(kDomain), "list"});
  EXPECT_EQ(env.exit_code, 2);
  EXPECT_NE(env.err.find("expired"), std::string::npos) << env.err;
  fs::remove_all(dir);
}

// --- the checks one by one -----------------------------------------------------------

class CheckTest : public ::testing::Test {
 protected:
  security::Settings s_ = settings_of("rack");

  // check()'s one line, or "" if it passed.
  std::string refusal(std::time_t now = std::time(nullptr)) {
    try {
      (void)security::check(s_, now);
      return {};
    } catch (const security::CheckError& e) {
      return e.what();
    }
  }
  fs::path scratch(const std::string& name, const std::string& content) {
    const auto p =
        fs::temp_directory_path() / ("dnbridge-check-" + std::to_string(getpid()) + "-" + name);
    std::ofstream(p, std::ios::binary) << content;
    files_.push_back(p);
    return p;
  }
  void TearDown() override {
    for (const auto& f : files_) fs::remove(f);
  }
  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

 private:
  std::vector<fs::path> files_;
};

TEST_F(CheckTest, TheScriptsFilesPass) {
  for (const char* name : {"rack", "scada", "ops"}) {
    s_ = settings_of(name);
    EXPECT_EQ(refusal(), "") << name;
  }
  const auto identity = security::check(settings_of("scada"));
  EXPECT_EQ(identity.subject, "CN=scada,OU=supervisor,O=test-site");
  EXPECT_NE(identity.valid_until.find(" UTC"), std::string::npos);
}

TEST_F(CheckTest, CertificatesAreCheckedAtTheirDates) {
  // 2019: before the certificates (issued today) were valid.
  EXPECT_NE(refusal(1546300800).find("identity CA is not valid before "), std::string::npos);
  // In 11 years the 10-year CAs have expired.
  EXPECT_NE(refusal(std::time(nullptr) + 11L * 365 * 86400).find("identity CA expired on"),
            std::string::npos);
  // In 2 years the 1-year identity has expired, the CA not.
  const auto later = refusal(std::time(nullptr) + 2L * 365 * 86400);
  EXPECT_EQ(later.rfind(s_.certificate.string() + ": identity certificate expired on ", 0), 0u)
      << later;
}

// X509_cmp_time's "cannot compare" is an error, for either date.
TEST_F(CheckTest, ADateOpenSslCannotReadIsRefused) {
  s_.identity_ca = kPki / "bad-date" / "not_before.pem";
  EXPECT_EQ(refusal(), s_.identity_ca.string() + ": identity CA has an unreadable notBefore date");
  s_.identity_ca = kPki / "bad-date" / "not_after.pem";
  EXPECT_EQ(refusal(), s_.identity_ca.string() + ": identity CA has an unreadable notAfter date");
}

TEST_F(CheckTest, EachFileIsWhatItsKeySays) {
  const auto good = s_;
  s_.identity_ca = good.private_key;
  EXPECT_EQ(refusal(),
            good.private_key.string() + ": is not a PEM certificate (the identity CA is one)");
  s_ = good;
  s_.private_key = good.certificate;
  EXPECT_EQ(refusal(), good.certificate.string() + ": is not a PEM private key");
  s_ = good;
  s_.private_key = host("scada") / "key.pem";  // another identity's key
  EXPECT_EQ(refusal(), s_.private_key.string() +
                           ": is not the private key of the identity certificate " +
                           good.certificate.string());
  s_ = good;
  s_.governance = good.permissions;
  EXPECT_EQ(refusal(), good.permissions.string() +
                           ": is signed, but it is not a governance document (no "
                           "<domain_access_rules> in it)");
  s_ = good;
  s_.permissions = kPki / "site" / "permissions.xml";  // not signed
  EXPECT_NE(refusal().find("permissions.xml: is not an S/MIME signed document"), std::string::npos);
  s_ = good;
  s_.permissions_ca = fs::temp_directory_path();
  EXPECT_EQ(refusal(), s_.permissions_ca.string() + ": is a directory, not a file");
  s_ = good;
  s_.identity_ca = scratch("empty.pem", "");
  EXPECT_EQ(refusal(), s_.identity_ca.string() + ": is empty");
}

TEST_F(CheckTest, ATamperedDocumentFailsItsSignature) {
  // One permission more, in the signed text.
  std::string p7s = read(s_.permissions);
  const std::string granted = "<topic>dnbridge/PumpCommand</topic>";
  const auto at = p7s.find(granted);
  ASSERT_NE(at, std::string::npos);
  p7s.replace(at, granted.size(), granted + "<topic>dnbridge/PumpState</topic>");
  s_.permissions = scratch("tampered.p7s", p7s);
  const auto r = refusal();
  EXPECT_EQ(r.rfind(s_.permissions.string() +
                        ": permissions document signature does not verify with the permissions CA ",
                    0),
            0u)
      << r;
}

TEST_F(CheckTest, AnEncryptedKeyIsRefusedWithoutAsking) {
  const auto encrypted = scratch("encrypted.pem", "");
  ASSERT_EQ(run("/usr/bin/openssl", {"pkey", "-in", s_.private_key.string(), "-aes256", "-passout",
                                     "pass:secret", "-out", encrypted.string()})
                .exit_code,
            0);
  s_.private_key = encrypted;
  EXPECT_EQ(refusal(), encrypted.string() +
                           ": private key is encrypted: give it unencrypted, readable by this "
                           "program's user only");
}

TEST_F(CheckTest, MissingPluginsAreNamed) {
  s_.plugin_directory = "/nonexistent";
  EXPECT_EQ(refusal(),
            "/nonexistent/libdds_security_auth.so: Cyclone DDS security plugin: No such file or "
            "directory (Debian package libddsc0debian; or set [security] plugins to the "
            "directory that has it)");
}

// --- the [security] table ---------------------------------------------------------------

TEST(SecurityTable, RelativePathsAreTheFilesNeighbours) {
  const auto s = settings_of("rack");
  EXPECT_EQ(s.certificate, host("rack") / "cert.pem");
  EXPECT_EQ(s.governance, host("rack") / "governance.p7s");
  EXPECT_EQ(s.plugin_directory, security::Settings::default_plugin_directory());
  // Properties Cyclone takes: the files as file: URIs, the plugins by path.
  const auto properties = security::participant_properties(s);
  std::map<std::string, std::string> p;
  for (const auto& [name, value] : properties) p[name] = value;
  EXPECT_EQ(p.at("dds.sec.auth.identity_certificate"), "file:" + s.certificate.string());
  EXPECT_EQ(p.at("dds.sec.access.permissions"), "file:" + s.permissions.string());
  EXPECT_EQ(
      p.at("dds.sec.crypto.library.path"),
      (security::Settings::default_plugin_directory() / "libdds_security_crypto.so").string());
  EXPECT_EQ(p.size(), 15u);
}

// The example's commented-out [security] table, uncommented, is what it says.
TEST(SecurityTable, TheExampleConfigurationsTable) {
  std::ifstream in(fs::path(DNBRIDGE_SOURCE_DIR) / "deploy/config/rack-example.toml");
  std::string text;
  bool in_table = false;
  for (std::string line; std::getline(in, line);) {
    in_table = in_table || line == "# [security]";
    if (in_table && line.rfind("# ", 0) == 0 && line.find(" = ") != std::string::npos) {
      line.erase(0, 2);
    } else if (in_table && line == "# [security]") {
      line = "[security]";
    }
    text += line + "\n";
  }
  ASSERT_TRUE(in_table);
  const auto c = daemon::parse_config(text, "rack-example.toml");
  ASSERT_TRUE(c.security);
  EXPECT_EQ(c.security->certificate, "security/etch-3-rack-A/cert.pem");
  EXPECT_EQ(c.security->permissions, "security/etch-3-rack-A/permissions.p7s");
  EXPECT_EQ(c.security->plugin_directory, "/usr/lib/x86_64-linux-gnu/libddsc0debian");
}

TEST(SecurityTable, InTheRackConfiguration) {
  const auto config = write_rack_config("table",
                                        "\n[security]\nidentity_ca = \"a/ca.pem\"\n"
                                        "certificate = \"/abs/cert.pem\"\nprivate_key = \"k.pem\"\n"
                                        "permissions_ca = \"p.pem\"\ngovernance = \"g.p7s\"\n"
                                        "permissions = \"q.p7s\"\nplugins = \"plugins\"\n");
  const auto c = daemon::load_config_file(config);
  fs::remove(config);
  ASSERT_TRUE(c.security);
  EXPECT_EQ(c.security->identity_ca, config.parent_path() / "a/ca.pem");
  EXPECT_EQ(c.security->certificate, "/abs/cert.pem");
  EXPECT_EQ(c.security->plugin_directory, config.parent_path() / "plugins");
  EXPECT_FALSE(daemon::embedded_default_config().security);

  try {
    (void)daemon::parse_config(
        "rack = \"r\"\n[security]\ncertificate = 5\n[[port]]\nname = \"A\"\n"
        "interface = \"simulated\"\nbitrate = 500000\n",
        "t.toml");
    FAIL() << "accepted";
  } catch (const daemon::ConfigError& e) {
    const auto& p = e.problems();
    ASSERT_EQ(p.size(), 6u) << e.what();
    EXPECT_EQ(p[0], "t.toml:2:1: missing required key 'identity_ca' in [security]");
    EXPECT_EQ(p.back(),
              "t.toml:3:15: security.certificate must be a file path (a non-empty string)");
  }
}

}  // namespace
}  // namespace dnbridge::security_test
