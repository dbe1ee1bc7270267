// The real dnbctl program, run as a child process, against a bridge of the
// simulated rack (eight CDN127 pumps at MACs 1..8 on port "A") running in
// this process, under a rack name and a node name that are not ASCII, taking commands from
// writers offering a lease of at most 1.5 s. Both are pinned to loopback
// on a domain and discovery tag of this process's own (test_domain.hpp). Node 3 holds its last
// outputs when no commander is left, so what one dnbctl run commanded is still applied when the
// next one reads it.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/daemon.hpp"
#include "adapters/daemon/log_sink.hpp"
#include "adapters/daemon/simulated_backends.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "subprocess.hpp"
#include "test_domain.hpp"

namespace dnbridge::dnbctl {
namespace {

using testing::RunResult;
using testing::test_domain;

// Bounds every wait for the bridge; never reached when things work.
constexpr auto kReady = std::chrono::seconds(10);

// UTF-8 names: "ätz-3 ラック" (9 characters in 15 bytes, 12 columns on a
// terminal: the katakana are wide) and "Pumpe ä-2".
constexpr const char* kRack = "\xC3\xA4tz-3 \xE3\x83\xA9\xE3\x83\x83\xE3\x82\xAF";
constexpr const char* kNode2 = "Pumpe \xC3\xA4-2";

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

constexpr unsigned kUnconfigured = 17;

class DnbctlEndToEnd : public ::testing::Test {
 protected:
  // The bridge's configuration; what a reload reads is this with
  // `reload_edit_` applied, or, when `reload_problem_` is set, a file with
  // that problem.
  static daemon::DaemonConfig suite_config() {
    daemon::DaemonConfig config = daemon::embedded_default_config();
    config.source = "dnbctl-e2e.toml";
    config.domain_id = test_domain();
    config.rack = kRack;
    // Below the lease dnbctl offers on its own (dnbctl::kCommandLease): it
    // offers the rack's bound, read from PortStatus, or commands nothing.
    config.max_commander_lease = milliseconds(1500);
    for (auto& node : config.ports.at(0).nodes) {
      if (node.pump.node.mac.value() == 3) {
        node.pump.no_commander = daemon::NoCommanderPolicy::kHoldLastOutputs;
      }
      if (node.pump.node.mac.value() == 2) node.pump.node.name = kNode2;
    }
    // A CDN127 the configuration does not have (a MAC switch set wrong).
    config.ports.at(0).simulated_unconfigured = {devicenet::MacId::from(kUnconfigured).value()};
    return config;
  }

  static void SetUpTestSuite() {
    log_ = std::make_unique<daemon::StderrLogSink>(LogLevel::kWarn);
    daemon::ReloadSource reload;
    reload.load = [] {
      if (!reload_problem_.empty()) throw daemon::ConfigError({reload_problem_});
      auto c = suite_config();
      if (reload_edit_) reload_edit_(c);
      return c;
    };
    bridge_ = std::make_unique<daemon::Daemon>(
        suite_config(), *log_, daemon::simulated_backend_factory(*log_), std::move(reload));
    bridge_->start();
    observer_ = std::make_unique<Observer>();
  }

  static void TearDownTestSuite() {
    observer_.reset();
    if (bridge_) bridge_->stop();
    bridge_.reset();
    log_.reset();
  }

  // What the test sees of the bridge itself: PumpState, and every
  // PumpCommand any dnbctl wrote.
  struct Observer {
    dds::Participant participant{static_cast<dds_domainid_t>(test_domain()),
                                 dds::Participant::ClientName{"dnbctl test observer"}};
    dds::Topic<dnbridge_PumpState> pump_topic{participant};
    dds::Topic<dnbridge_PumpCommand> command_topic{participant};
    dds::Reader<dnbridge_PumpState> pumps{participant, pump_topic, dds::state_reader_qos()};
    dds::Reader<dnbridge_PumpCommand> commands{
        participant, command_topic, dds::command_reader_qos(dds::rack_partitions(kRack))};
    dds::WaitSet waitset{participant};
    std::map<unsigned, dds::Owned<dnbridge_PumpState>> latest;
    std::vector<std::uint16_t> commanded_analog;  // every command's analog_output_raw

    Observer() {
      (void)pumps.set_status_mask(DDS_DATA_AVAILABLE_STATUS);
      waitset.attach(pumps, 1);
    }

    void take() {
      if (auto samples = pumps.take()) {
        for (auto& s : *samples) {
          if (!s.valid_data()) continue;
          std::swap(*latest[s->mac], s.data());
        }
      }
      if (auto samples = commands.take()) {
        for (auto& s : *samples) {
          if (s.valid_data()) commanded_analog.push_back(s->analog_output_raw);
        }
      }
    }

    // Until the latest PumpState of `mac` satisfies `ok`; false after kReady.
    template <class Pred>
    bool wait_pump(unsigned mac, Pred ok) {
      const auto deadline = std::chrono::steady_clock::now() + kReady;
      for (;;) {
        take();
        auto it = latest.find(mac);
        if (it != latest.end() && ok(*it->second)) return true;
        if (std::chrono::steady_clock::now() >= deadline) return false;
        (void)waitset.wait(milliseconds(100));
      }
    }
  };

  void SetUp() override {
    ASSERT_TRUE(bridge_);
    // Ready: every pump online and polled with inputs.
    for (unsigned mac = 1; mac <= 8; ++mac) {
      ASSERT_TRUE(observer_->wait_pump(
          mac, [](const dnbridge_PumpState& s) { return s.online && s.inputs_valid; }))
          << "pump " << mac << " did not come online";
    }
  }

  // dnbctl on this process's domain.
  static RunResult dnbctl(std::vector<std::string> args) {
    args.insert(args.begin(), {"--domain", std::to_string(test_domain())});
    return testing::run(DNBCTL_PATH, args);
  }

  static std::unique_ptr<daemon::StderrLogSink> log_;
  static std::unique_ptr<daemon::Daemon> bridge_;
  static std::unique_ptr<Observer> observer_;
  // What the next reload reads (set before the dnbctl run that asks for it).
  static inline std::function<void(daemon::DaemonConfig&)> reload_edit_;
  static inline std::string reload_problem_;
};

std::unique_ptr<daemon::StderrLogSink> DnbctlEndToEnd::log_;
std::unique_ptr<daemon::Daemon> DnbctlEndToEnd::bridge_;
std::unique_ptr<DnbctlEndToEnd::Observer> DnbctlEndToEnd::observer_;

TEST_F(DnbctlEndToEnd, ListShowsTheEightNodesOnline) {
  const auto json = dnbctl({"list", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_NE(json.out.find(std::string("\"rack\": \"") + kRack + "\""), std::string::npos)
      << json.out;
  EXPECT_NE(json.out.find("\"nodes_online\": 8"), std::string::npos) << json.out;
  EXPECT_EQ(count(json.out, "\"online\": true"), 8u) << json.out;
  EXPECT_EQ(count(json.out, "\"product\": \"CDN127\""), 8u) << json.out;

  const auto table = dnbctl({"list"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("8/8 online"), std::string::npos) << table.out;
  EXPECT_EQ(count(table.out, "  online  yes  "), 8u) << table.out;
}

TEST_F(DnbctlEndToEnd, NonAsciiNamesRoundTripThroughJsonAndAlignInTables) {
  const auto r = dnbctl({"list", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Parsed by a JSON library of its own: the names come back as configured.
  const auto doc = nlohmann::json::parse(r.out);
  std::vector<std::string> racks;
  std::map<unsigned, std::string> names;
  for (const auto& rack : doc.at("racks")) {
    racks.push_back(rack.at("rack").get<std::string>());
    for (const auto& port : rack.at("ports")) {
      for (const auto& node : port.at("nodes")) {
        names[node.at("mac").get<unsigned>()] = node.at("name").get<std::string>();
      }
    }
  }
  EXPECT_EQ(racks, std::vector<std::string>{kRack});
  EXPECT_EQ(names.size(), 8u);
  EXPECT_EQ(names[2], kNode2);
  EXPECT_EQ(names[3], "pump-3");

  // In the nodes' table, columns are padded to the width a terminal gives
  // the names (the rack 12 columns, node 2's name 9), not to their bytes.
  const auto table = dnbctl({"list", "--nodes"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  const std::string rack(kRack);
  for (const std::string& line : std::vector<std::string>{
           "RACK          PORT  MAC  NAME       STATE   ONLINE  PRODUCT  REASON\n",
           rack + "  A     2    " + kNode2 + "  online  yes     CDN127   polled",
           rack + "  A     3    pump-3     online  yes     CDN127   polled"}) {
    EXPECT_NE(table.out.find(line), std::string::npos) << line << "\nin:\n" << table.out;
  }
}

// dnbctl scan: the bridge itself, its eight nodes online, and the CDN127 at
// MAC 17 that the configuration does not have, with its identity and the
// lines that would configure it; nothing at the other MACs. A second scan
// within 30 s is the first one again, at once.
TEST_F(DnbctlEndToEnd, ScanFindsTheUnconfiguredNodeAndSaysHowToConfigureIt) {
  const auto started = std::chrono::steady_clock::now();
  const auto r = dnbctl({"scan", "--json"});
  const double first_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const auto doc = nlohmann::json::parse(r.out);
  std::map<unsigned, nlohmann::json> nodes;
  for (const auto& n : doc.at("nodes")) nodes[n.at("mac").get<unsigned>()] = n;
  ASSERT_EQ(nodes.size(), 10u) << r.out;
  EXPECT_EQ(nodes.at(0).at("found"), "master");
  for (unsigned mac = 1; mac <= 8; ++mac) {
    const auto& n = nodes.at(mac);
    EXPECT_EQ(n.at("configured"), true) << n;
    EXPECT_EQ(n.at("state"), "online") << n;
    EXPECT_EQ(n.at("vendor_id"), 59) << n;
    EXPECT_EQ(n.at("product_code"), 1888) << n;
    EXPECT_EQ(n.at("rack"), kRack);
    EXPECT_EQ(n.at("port"), "A");
  }
  const auto& found = nodes.at(kUnconfigured);
  EXPECT_EQ(found.at("configured"), false) << found;
  EXPECT_EQ(found.at("found"), "identified") << found;
  EXPECT_EQ(found.at("vendor_id"), 59);
  EXPECT_EQ(found.at("product_type"), 27);
  EXPECT_EQ(found.at("product_code"), 1888);
  EXPECT_EQ(found.at("serial_number"), kUnconfigured);  // the simulator's, as a UINT
  EXPECT_EQ(found.at("product_name"), "CDN127");
  const std::string lines = found.at("suggested_configuration").get<std::string>();
  EXPECT_NE(lines.find("[[port.node]]\n  mac = 17\n"), std::string::npos) << lines;
  EXPECT_NE(lines.find("serial = 0x00000011"), std::string::npos) << lines;
  const auto& port = doc.at("ports").at(0);
  EXPECT_EQ(port.at("status"), 1) << port;
  EXPECT_EQ(port.at("silent_macs").size(), 54u) << port;
  std::printf(
      "[ measured ] dnbctl scan (the bridge's first, 55 MACs asked): %.1f s; the scan "
      "itself %u ms\n",
      first_s, port.at("duration_ms").get<unsigned>());

  // Again, as a table: the same scan, not the bus asked again.
  const auto again = dnbctl({"scan"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("\n17   unconfigured                         59      27    1888  "
                           "1.5       0x00000011  CDN127\n"),
            std::string::npos)
      << again.out;
  EXPECT_NE(again.out.find("1    configured, online"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("the bus scan of"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("  [[port.node]]\n  mac = 17\n  name = \"node-17\"\n"),
            std::string::npos)
      << again.out;
}

TEST_F(DnbctlEndToEnd, ShowShowsTheIdentity) {
  const auto r = dnbctl({"show", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* line :
       {"node                      \xC3\xA4tz-3 \xE3\x83\xA9\xE3\x83\x83\xE3\x82\xAF/A/3 "
        "(pump-3)\n",
        "state                     online\n", "product name              CDN127\n",
        "vendor                    59 (0x003B)\n", "product code              1888 (0x0760)\n",
        "serial number             3 (0x00000003)\n"}) {
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\nin:\n" << r.out;
  }
  const auto json = dnbctl({"show", "3", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_NE(json.out.find("\"product_name\": \"CDN127\""), std::string::npos) << json.out;

  const auto absent = dnbctl({"show", "9", "--timeout", "0.5"});
  EXPECT_EQ(absent.exit_code, 3);
  EXPECT_NE(absent.err.find("no bridge reported a node with MAC 9"), std::string::npos)
      << absent.err;
  // The bridge was heard: no list of causes for not reaching one.
  EXPECT_EQ(absent.err.find("Likely causes"), std::string::npos) << absent.err;
}

TEST_F(DnbctlEndToEnd, NodesAreNamedByMacOrByName) {
  auto r = dnbctl({"show", kNode2});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(std::string(kRack) + "/A/2 (" + kNode2 + ")"), std::string::npos) << r.out;

  r = dnbctl({"get", "pump-4", "0x01", "1", "6", "--as", "uint"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("/A/4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("as uint: 4\n"), std::string::npos) << r.out;  // the serial number

  r = dnbctl({"show", "pump4", "--timeout", "0.5"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no bridge reported a node named \"pump4\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(did you mean \"pump-4\"?)"), std::string::npos) << r.err;
}

TEST_F(DnbctlEndToEnd, OutputCommandsAreAppliedAndKeepTheOtherOutputs) {
  auto r = dnbctl({"pump", "3", "on"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(std::string(kRack) + "/A/3 (pump-3): applied: pump on"), std::string::npos)
      << r.out;
  EXPECT_TRUE(observer_->wait_pump(3, [](const dnbridge_PumpState& s) {
    return !s.outputs_idle && s.pump_on && dds::view(s.commanded_by).starts_with("dnbctl ");
  }));

  // 5.0 V: round(5.0 * 4095 / 10) = round(2047.5) = 2048; the pump stays on.
  r = dnbctl({"aout", "3", "5.0V"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("applied: pump on, N2 ballast off, analog out 2048"), std::string::npos)
      << r.out;
  EXPECT_TRUE(observer_->wait_pump(3, [](const dnbridge_PumpState& s) {
    return !s.outputs_idle && s.pump_on && s.analog_output_raw == 2048;
  }));

  // Out of range: refused on the command line, nothing sent.
  r = dnbctl({"aout", "3", "11V"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("analog value 11 V is out of range 0..10 V"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;

  r = dnbctl({"ballast", "3", "on", "--json", "--issuer", "test bench"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"applied\": true"), std::string::npos) << r.out;
  EXPECT_TRUE(observer_->wait_pump(3, [](const dnbridge_PumpState& s) {
    return !s.outputs_idle && s.pump_on && s.n2_ballast_on && s.analog_output_raw == 2048 &&
           dds::view(s.commanded_by) == "test bench";
  }));

  // Every command any dnbctl wrote was in range: the 11 V one never left.
  observer_->take();
  ASSERT_FALSE(observer_->commanded_analog.empty());
  for (auto raw : observer_->commanded_analog) EXPECT_LE(raw, 4095);
  EXPECT_EQ(observer_->commanded_analog.back(), 2048);
}

TEST_F(DnbctlEndToEnd, ExplicitMessaging) {
  auto r = dnbctl({"get", "3", "1", "1", "7", "--as", "string"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("status: 1 (transaction completed)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("data (7 bytes): 06 43 44 4E 31 32 37\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("as string: \"CDN127\"\n"), std::string::npos) << r.out;

  r = dnbctl({"get", "3", "0x01", "1", "1", "--as", "uint", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"value\": 59"), std::string::npos) << r.out;  // vendor ID

  r = dnbctl({"get", "3", "1", "1", "99"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("CIP general status: 0x14 (attribute not supported)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("attribute not supported"), std::string::npos) << r.err;

  r = dnbctl({"get", "40", "1", "1", "1"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("status: 3 (slave not in scan list)"), std::string::npos) << r.out;

  // Refused by the bridge's explicit policy (the embedded default's): the
  // user sees why and what would allow it.
  r = dnbctl({"set", "3", "9", "1", "3", "01"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("status: 8 (invalid command code)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("message: Set_Attribute_Single (0x10) of Discrete Output Point instance 1 "
                       "Value is an output write, which the explicit policy refuses. Risk: "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("status 8 (invalid command code): Set_Attribute_Single (0x10) of Discrete "
                       "Output Point instance 1 Value"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("allow_output_writes = true in [explicit_policy] allows it"),
            std::string::npos)
      << r.err;
}

// No bridge needed: these end before (or for lack of) any answer.
TEST(Dnbctl, UsageErrorsExit2AndNothingFoundExits3) {
  const std::string domain = std::to_string(test_domain() + 1);  // no bridge there
  auto r = testing::run(DNBCTL_PATH, {"--domain", domain, "pump", "64", "on"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("MAC ID 64 is out of range 0..63"), std::string::npos) << r.err;

  r = testing::run(DNBCTL_PATH, {"frobnicate"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown command \"frobnicate\"; dnbctl --help lists them"),
            std::string::npos)
      << r.err;
  r = testing::run(DNBCTL_PATH, {"--domain", domain, "lsit"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown command \"lsit\" (did you mean \"list\"?)"), std::string::npos)
      << r.err;
  r = testing::run(DNBCTL_PATH, {"--domian", domain, "list"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown option \"--domian\" (did you mean \"--domain\"?)"),
            std::string::npos)
      << r.err;
  r = testing::run(DNBCTL_PATH, {"pump", "3", "on", "--strenght", "5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("(did you mean \"--strength\"?)"), std::string::npos) << r.err;
  r = testing::run(DNBCTL_PATH, {"get", "3", "1", "1", "7", "--as", "float"});
  EXPECT_EQ(r.exit_code, 2);
  r = testing::run(DNBCTL_PATH, {"set", "3", "1", "1", "7", "abc"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("two hex digits"), std::string::npos) << r.err;

  r = testing::run(DNBCTL_PATH, {"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos);
  r = testing::run(DNBCTL_PATH, {"pump", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--hold-for"), std::string::npos);
  EXPECT_NE(r.out.find("only while a commander is live"), std::string::npos);

  r = testing::run(DNBCTL_PATH, {"--domain", domain, "--timeout", "0.5", "list"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no bridge answered on DDS domain " + domain), std::string::npos) << r.err;
  // What it used and what to check: the domain, the network configuration
  // (the tests set CYCLONEDDS_URI), a firewall, DDS Security.
  EXPECT_NE(r.err.find("dnbctl looked on DDS domain " + domain +
                       " (--domain, $DNBCTL_DOMAIN) "
                       "with CYCLONEDDS_URI="),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("a firewall drops DDS's UDP traffic"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(--security)"), std::string::npos) << r.err;
  r = testing::run(DNBCTL_PATH, {"--domain", domain, "--timeout", "0.5", "racks"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no bridge answered on DDS domain " + domain), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dnbridge::dnbctl

namespace dnbridge::dnbctl {
namespace {

// dnbctl reload: the bridge reads its configuration again. Unchanged, it
// applies nothing; with a node renamed, that change; with a problem,
// nothing, and dnbctl says why and exits 1.
TEST_F(DnbctlEndToEnd, ReloadAppliesWhatChangedAndReportsProblems) {
  const auto unchanged = dnbctl({"reload", "--json"});
  ASSERT_EQ(unchanged.exit_code, 0) << unchanged.err << unchanged.out;
  const auto doc = nlohmann::json::parse(unchanged.out);
  EXPECT_EQ(doc.at("rack"), kRack);
  EXPECT_EQ(doc.at("status"), "applied");
  EXPECT_EQ(doc.at("file"), "dnbctl-e2e.toml");
  EXPECT_TRUE(doc.at("applied").empty()) << doc;
  EXPECT_TRUE(doc.at("problems").empty()) << doc;

  reload_edit_ = [](daemon::DaemonConfig& c) { c.ports.at(0).nodes.at(5).pump.node.name = "six"; };
  const auto renamed = dnbctl({"--rack", kRack, "reload"});
  ASSERT_EQ(renamed.exit_code, 0) << renamed.err << renamed.out;
  EXPECT_NE(renamed.out.find("port A: node 6 name or policies changed"), std::string::npos)
      << renamed.out;
  EXPECT_TRUE(observer_->wait_pump(
      6, [](const dnbridge_PumpState& s) { return dds::view(s.name) == "six" && s.online; }));

  reload_problem_ = "dnbctl-e2e.toml:12:3: poll_period_ms must be positive";
  const auto refused = dnbctl({"reload", "--json"});
  reload_problem_.clear();
  EXPECT_EQ(refused.exit_code, 1) << refused.err << refused.out;
  const auto no = nlohmann::json::parse(refused.out);
  EXPECT_EQ(no.at("status"), "refused");
  ASSERT_EQ(no.at("problems").size(), 1u) << no;
  EXPECT_EQ(no.at("problems").at(0), "dnbctl-e2e.toml:12:3: poll_period_ms must be positive");
  EXPECT_NE(refused.err.find("reload refused"), std::string::npos) << refused.err;

  // Back as the other tests know it.
  reload_edit_ = nullptr;
  const auto back = dnbctl({"reload"});
  EXPECT_EQ(back.exit_code, 0) << back.err << back.out;
  EXPECT_TRUE(observer_->wait_pump(
      6, [](const dnbridge_PumpState& s) { return dds::view(s.name) == "pump-6"; }));
}

}  // namespace
}  // namespace dnbridge::dnbctl
