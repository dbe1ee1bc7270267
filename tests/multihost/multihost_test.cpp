// Many hosts on a real network: network namespaces made by the test, each
// with one veth cable to a Linux bridge (the plant switch, in a namespace of
// its own), and Cyclone DDS configured as deploy/cyclonedds/cyclonedds.xml
// ships it (multicast discovery on the host's network interface). Nothing
// of this machine's own network is touched. Needs root (CI runs as root):
// without it the test fails, it is not skipped.
//
// The hosts: the bridges of racks "rack-a" and "rack-b" (dnbridge-sim on the
// simulated rack), the supervisory host "sup-a" (dnbridge_plant_host), whose
// DDS Security permissions cover rack-a only, and a host without a
// certificate of the site. The PKI is made by deploy/security/make-site-pki.sh.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "e2e/child_process.hpp"
#include "support/plant_network.hpp"
#include "support/simulated_rack.hpp"

namespace dnbridge::multihost_test {
namespace {

namespace fs = std::filesystem;
using e2e::ChildOptions;
using e2e::ChildProcess;
using plant::PlantNetwork;
using plant::sh;
using std::chrono::milliseconds;

constexpr int kDomain = 42;
// Each rack is the simulated rack of `dnbridge-sim --simulate`: 8 pumps.
constexpr int kPumpsPerRack = 8;
// The state topics' deadline on that rack: twice its 1 s publish period.
constexpr int kFreshMs = 2000;
// How soon after a cable comes back a supervisor's view is complete again
// (measured: deploy/README.md, "A fleet on one plant network").
// Within the participant lease, reliable delivery resumes at once; after
// it, rediscovery waits for the next SPDP message (deploy's SPDPInterval,
// 2 s) and a new DDS Security handshake.
constexpr double kShortCutRecoverySeconds = 2.0;
constexpr double kLongCutRecoverySeconds = 3.5;

std::int64_t monotonic_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

// dnbridge_plant_host on a plant host.
class PlantHost : public plant::HostProgram {
 public:
  PlantHost(const PlantNetwork& net, const std::string& host, std::vector<std::string> args)
      : HostProgram(
            net, host,
            [&] {
              args.insert(args.begin(), DNBRIDGE_PLANT_HOST);
              return args;
            }(),
            plant::deployed_cyclone(true)) {}
};

// The time in a "view complete T" or "view incomplete T N" line.
std::int64_t view_time(const std::string& line) {
  std::istringstream in(line);
  std::string view, state;
  std::int64_t t = 0;
  in >> view >> state >> t;
  return t;
}

// The plant: rack-a's and rack-b's bridges, the supervisory host sup-a and
// the outsider, each on a host of its own; the supervisor has seen every
// pump and rack-a's pump 1 is online.
class MultiHostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(geteuid(), 0u) << "the multi-host test makes network namespaces: it needs root";
    work_ = fs::temp_directory_path() / ("dnbridge-multihost-" + std::to_string(getpid()));
    fs::remove_all(work_);
    fs::create_directories(work_);
    ASSERT_TRUE(sh("bash " DNBRIDGE_SOURCE_DIR "/deploy/security/make-site-pki.sh --out " +
                   (work_ / "pki").string() + " --domain " + std::to_string(kDomain) +
                   " --site plant-test --bridge bridge-a=rack-a --bridge bridge-b=rack-b"
                   " --supervisor sup-a=rack-a >" +
                   (work_ / "pki.log").string()));
    net_.emplace(std::vector<std::string>{"rack-a", "rack-b", "sup-a", "outsider"});
    ASSERT_TRUE(net_->ok());
    bridge_a_.emplace(
        net_->on("rack-a", {DNBRIDGE_BINARY, "--config", rack_config("rack-a", "bridge-a")}),
        plant::deployed_cyclone(false));
    bridge_b_.emplace(
        net_->on("rack-b", {DNBRIDGE_BINARY, "--config", rack_config("rack-b", "bridge-b")}),
        plant::deployed_cyclone(false));
    const std::vector<std::string> view{std::to_string(kDomain), std::to_string(2 * kPumpsPerRack),
                                        std::to_string(kFreshMs)};
    const auto started = monotonic_ns();
    auto with_identity = view;
    with_identity.insert(with_identity.end(), {"--security", security("sup-a").string()});
    sup_.emplace(*net_, "sup-a", with_identity);
    outsider_.emplace(*net_, "outsider", view);

    const auto complete = sup_->until("view complete", milliseconds(60000));
    ASSERT_TRUE(complete) << "the supervisor never saw all " << 2 * kPumpsPerRack << " pumps:\n"
                          << sup_->transcript();
    std::printf("supervisor's view complete %.2f s after it started (discovery, DDS Security)\n",
                static_cast<double>(view_time(*complete) - started) / 1e9);
    // A command applies to a node online.
    ASSERT_TRUE(sup_->send("show rack-a A 1"));
    const auto now = sup_->until("shown node rack-a A 1 ");
    ASSERT_TRUE(now) << sup_->transcript();
    if (now->find(" online=1 ") == std::string::npos) {
      ASSERT_TRUE(sup_->until("node rack-a A 1 online=1")) << sup_->transcript();
    }
  }

  void TearDown() override {
    outsider_.reset();
    sup_.reset();
    for (auto* bridge : {&bridge_a_, &bridge_b_}) {
      if (!*bridge) continue;
      EXPECT_TRUE((*bridge)->signal(SIGTERM));
      EXPECT_EQ((*bridge)->wait(), 0) << "a bridge did not stop cleanly";
    }
    net_.reset();
    fs::remove_all(work_);
  }

  fs::path security(const std::string& identity) const {
    return work_ / "pki" / "hosts" / identity / "security.toml";
  }

  // The simulated rack as rack `rack`, logging at info level, with the
  // bridge identity `identity` of the site: written beside that identity's
  // files, which its [security] table names relative to itself.
  std::string rack_config(const std::string& rack, const std::string& identity) const {
    // Rack-a's log is read (its commander's loss); rack-b's is not, and
    // says little at warn.
    const std::string text =
        support::simulated_rack_config(kDomain, rack, rack == "rack-a" ? "info" : "warn");
    std::stringstream table;
    table << std::ifstream(security(identity)).rdbuf();
    const fs::path path = security(identity).parent_path() / (rack + ".toml");
    std::ofstream(path) << text << "\n" << table.str();
    return path.string();
  }

  // The supervisor commands rack-a's pump 1 on, and it is applied.
  void command_pump_1() {
    ASSERT_TRUE(sup_->send("command rack-a A 1 on"));
    EXPECT_EQ(sup_->until("written"), "written rack-a 1");
    ASSERT_TRUE(sup_->until("node rack-a A 1 online=1 idle=0 pump_on=1 by=plant host"))
        << sup_->transcript();
  }

  // The supervisor's cable cut until `lost` appears in rack-a's bridge's
  // log (`bridge_log`), or else until the supervisor has lost both bridges
  // (every pump "gone"). Then it is
  // mended, and the supervisor's view must be complete again within
  // `bound` seconds. Returns how long that took.
  double cut_until(std::string_view lost, bool bridge_log, double bound) {
    EXPECT_TRUE(net_->cut("sup-a"));
    const auto cut = monotonic_ns();
    // The supervisor sees its view stale (no sample for kFreshMs) after the
    // cut, before or after `lost`.
    bool stale = false;
    std::set<std::string> gone;  // the supervisor's "node ... gone" lines, one per pump
    const auto watch = [&](const std::string& l) {
      stale = stale || (l.rfind("view incomplete", 0) == 0 && view_time(l) >= cut);
      if (l.rfind("node ", 0) == 0 && l.ends_with(" gone")) gone.insert(l);
      return stale && (bridge_log || gone.size() == 2 * kPumpsPerRack);
    };
    if (bridge_log) {
      EXPECT_TRUE(bridge_a_->read_stderr_until(log_a_, lost, milliseconds(30000))) << log_a_;
    } else {  // `lost` only names it in the report
      EXPECT_TRUE(sup_->until(watch, milliseconds(30000))) << sup_->transcript();
    }
    const auto seen = monotonic_ns();
    if (!stale) {
      EXPECT_TRUE(sup_->until(watch)) << sup_->transcript();
    }
    EXPECT_TRUE(net_->mend("sup-a"));
    const auto mended = monotonic_ns();
    std::printf("cable cut for %.2f s; \"%s\" %.2f s after the cut\n",
                static_cast<double>(mended - cut) / 1e9, std::string(lost).c_str(),
                static_cast<double>(seen - cut) / 1e9);
    const auto back = sup_->until(
        [&](const std::string& l) {
          return l.rfind("view complete", 0) == 0 && view_time(l) >= mended;
        },
        milliseconds(60000));
    EXPECT_TRUE(back) << sup_->transcript();
    if (!back) return -1;
    const double recovery = static_cast<double>(view_time(*back) - mended) / 1e9;
    std::printf(
        "supervisor's view complete again %.3f s after the cable came back (bound %.1f s)\n",
        recovery, bound);
    EXPECT_LT(recovery, bound);
    return recovery;
  }

  // Rack-a's pump 1 is idle and waits for a new command; one is applied.
  void pump_1_idle_until_commanded_again() {
    ASSERT_TRUE(sup_->send("show rack-a A 1"));
    const auto now = sup_->until("shown node rack-a A 1 ");
    ASSERT_TRUE(now);
    EXPECT_EQ(now->rfind("shown node rack-a A 1 online=1 idle=1 pump_on=0", 0), 0u) << *now;
    command_pump_1();
  }

  // Nothing but rack-a's pump 1 was ever commanded: every other pump's line
  // the supervisor printed says idle, until two publish periods from now.
  void nothing_else_commanded() {
    // Every pump publishes at least once a second: two more samples of
    // each, and anything a command did shows.
    ASSERT_TRUE(sup_->send("wait-samples 2"));
    ASSERT_TRUE(sup_->until("samples 2", milliseconds(15000))) << sup_->transcript();
    std::istringstream lines(sup_->transcript());
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("node ", 0) != 0 || line.rfind("node rack-a A 1 ", 0) == 0 ||
          line.ends_with(" gone")) {
        continue;
      }
      EXPECT_NE(line.find(" idle=1 pump_on=0 "), std::string::npos) << line;
    }
  }

  fs::path work_;
  std::optional<PlantNetwork> net_;
  std::optional<ChildProcess> bridge_a_, bridge_b_;
  std::optional<PlantHost> sup_, outsider_;
  std::string log_a_;  // rack-a's bridge's log, as far as read
};

// Partitions and DDS Security across hosts: the supervisor's command to
// rack-a matches rack-a's bridge only and is applied; its permissions do not
// cover rack-b: its writer for rack-b is refused. A host without a
// certificate of the site sees nothing and its command reaches no bridge.
TEST_F(MultiHostTest, ASupervisorCommandsItsOwnRackOnly) {
  command_pump_1();
  ASSERT_TRUE(sup_->send("command rack-b A 1 on"));
  const auto refused = sup_->until([](const std::string& l) {
    return l.rfind("written", 0) == 0 || l.rfind("refused", 0) == 0;
  });
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->rfind("refused rack-b", 0), 0u) << *refused;
  // dnbctl on the supervisor's host, with its identity, says why.
  ChildOptions dnbctl_options = plant::deployed_cyclone(false);
  ChildProcess dnbctl(
      net_->on("sup-a", {DNBCTL_BIN, "--domain", std::to_string(kDomain), "--security",
                         security("sup-a").string(), "--rack", "rack-b", "pump", "1", "on"}),
      dnbctl_options);
  std::string dnbctl_says;
  EXPECT_TRUE(dnbctl.read_stderr_until(dnbctl_says, "Not Allowed By Security", milliseconds(20000)))
      << dnbctl_says;
  EXPECT_NE(dnbctl.wait_for(milliseconds(20000)).value_or(0), 0) << dnbctl_says;

  // (Its unauthenticated discovery would take far less than the
  // supervisor's authenticated one, which came first.)
  ASSERT_TRUE(outsider_->send("command rack-a A 2 on"));
  EXPECT_EQ(outsider_->until("written"), "written rack-a 0");
  ASSERT_TRUE(outsider_->send("status"));
  EXPECT_EQ(outsider_->until("status"), "status instances=0 samples=0");
  nothing_else_commanded();
}

// The supervisor's cable cut for longer than its commander's liveliness
// lease (2 s), shorter than the participant lease: rack-a's bridge idles the
// commanded pump; when the cable is back the supervisor's view is complete
// again at once (reliable delivery resumes), and the pump stays idle until
// a new command.
TEST_F(MultiHostTest, ACutLongerThanTheCommandLeaseIdlesThePump) {
  command_pump_1();
  cut_until("node 1: no live commander left", true, kShortCutRecoverySeconds);
  pump_1_idle_until_commanded_again();
  nothing_else_commanded();
}

// Cut for longer than the participant lease (deploy's cyclonedds.xml): the
// supervisor loses both bridges, they lose it. When the cable is back
// they find each other again at the next SPDP (deploy's SPDPInterval) and
// authenticate again; the view is complete again within kLongCutRecovery.
TEST_F(MultiHostTest, ACutLongerThanTheParticipantLeaseIsRediscovered) {
  command_pump_1();
  cut_until("both bridges gone", false, kLongCutRecoverySeconds);
  pump_1_idle_until_commanded_again();
  nothing_else_commanded();
}

}  // namespace
}  // namespace dnbridge::multihost_test
