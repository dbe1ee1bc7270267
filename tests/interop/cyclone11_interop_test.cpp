// Interoperability with a current Cyclone DDS release, in another language.
// The bridge (dnbridge-sim, on Debian's Cyclone DDS 0.10.2) against programs
// of Eclipse Cyclone DDS 11.0.1 and its Python binding: a supervisor written
// from idl/dnbridge.idl and idl/README.md alone (cyclone11_supervisor.py), its
// types generated at test time by that release's own generator (idlc -l py)
// from the tree's IDL, and the release's generic tool (cyclonedds typeof),
// which shows each topic's type as the bridge describes it over XTypes. The
// supervisor reads the rack's state and uses every command and request
// topic; the tool shows each of the bridge's twelve topics with the IDL's
// struct; and a reader of NodeStatus as it was before its safe state became
// members of its own (former_node_status.idl) is not matched at all.
//
// The release is a bundle (DNBRIDGE_CYCLONE11_BUNDLE: a Python virtual
// environment that works at /tmp/pydds only), unpacked there by
// cyclone11_bundle.sh when /tmp/pydds is not that bundle; without it the
// tests fail, they are not skipped. Everything on this host's loopback
// (deploy/cyclonedds/loopback.xml: unicast discovery), with a discovery tag
// of this process's own, so that runs side by side never meet.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "e2e/child_process.hpp"
#include "support/simulated_rack.hpp"

namespace dnbridge::interop_test {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// No other test uses it (the in-process tests take 100..199, the Fast DDS
// test 17, the multi-host test 42, the security test 230); the discovery tag
// keeps runs of this test apart.
constexpr int kDomain = 53;
constexpr char kRack[] = "sim-rack";
constexpr char kPort[] = "A";
constexpr int kPump = 1;     // a CDN127 of the embedded default rack
constexpr int kDevice = 20;  // the example I/O block, added (rack_config)

const fs::path kPydds = "/tmp/pydds";
const fs::path kPython = kPydds / "bin/python";
const fs::path kIdlc = kPydds / "cyclonedds-c/bin/idlc";
const fs::path kCli = kPydds / "bin/cyclonedds";
const fs::path kSupervisor = DNBRIDGE_SOURCE_DIR "/tests/interop/cyclone11_supervisor.py";

// The bundle's check, and its unpacking (a few seconds; the script waits
// up to 60 s for another run's unpacking).
constexpr milliseconds kBundleBound{90000};
constexpr milliseconds kIdlcBound{30000};
// The supervisor's own bounds (30 s for the rack's state, 15 s for the
// command, 20 s for the reply, 30 s for the device's command, the reload and
// the bus scan), and its start.
constexpr milliseconds kSupervisorBound{120000};
// The bridge found by a typeof's discovery scan, from the bridge's start.
constexpr milliseconds kBridgeFound{30000};
// One typeof: its discovery scan (kTypeofScan), then the resolution of the
// types it found over the type lookup service (as long again at most), and
// the start of Python.
constexpr char kTypeofScan[] = "3s";
constexpr milliseconds kTypeofBound{30000};
constexpr milliseconds kBridgeStop{20000};

// dnbridge/TOPIC carries dnbridge::TOPIC (adapters/dds/topics.hpp), for
// each of the bridge's topics; without DDS Security dnbridge-sim offers
// them all, the bus scan's and the reload's included.
const std::vector<std::string> kTopics = {"PumpState",       "PumpCommand",   "DeviceState",
                                          "DeviceCommand",   "NodeStatus",    "PortStatus",
                                          "ExplicitRequest", "ExplicitReply", "BusScanRequest",
                                          "BusScanReply",    "ReloadRequest", "ReloadReply"};

// The embedded default rack (pumps 1..8 on port A), logging at info (shown
// when a test fails), with the example I/O block (deploy/eds) at MAC 20 on
// change of state, as the Fast DDS test has it: a node whose DeviceState
// exists.
std::string rack_config() {
  std::string text = support::simulated_rack_config(kDomain, kRack, "info");
  text += support::example_io_block_node(DNBRIDGE_SOURCE_DIR);
  return text;
}

// Both Cyclone DDS releases read the same configuration: the shipped
// loopback one, and this process's discovery tag.
std::string cyclonedds_uri() {
  return "CYCLONEDDS_URI=file://" DNBRIDGE_SOURCE_DIR
         "/deploy/cyclonedds/loopback.xml,<CycloneDDS><Domain id=\"any\"><Discovery><Tag>"
         "dnbridge-cyclone11-" +
         std::to_string(getpid()) + "</Tag></Discovery></Domain></CycloneDDS>";
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

// A program of the bundle run to its end; its stdout read a line at a time,
// its stderr the test's own.
class Program {
 public:
  Program(std::vector<std::string> args, std::vector<std::string> env, std::string echo_prefix = {})
      : echo_(std::move(echo_prefix)) {
    e2e::ChildOptions options;
    options.control = true;
    options.env = std::move(env);
    options.env.push_back(cyclonedds_uri());
    child_.emplace(std::move(args), options);
  }

  // Its exit status, once it ended within `bound` (then what it printed is
  // in lines()); nullopt if it did not (it is killed when destroyed).
  std::optional<int> finish(milliseconds bound) {
    const auto deadline = Clock::now() + bound;
    for (;;) {
      const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return std::nullopt;
      auto line = child_->read_line(left);
      if (!line) break;  // its stdout closed, or the bound passed
      if (!echo_.empty()) std::printf("%s%s\n", echo_.c_str(), line->c_str());
      lines_.push_back(std::move(*line));
    }
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    return child_->wait_for(std::max(left, milliseconds(0)));
  }
  const std::vector<std::string>& lines() const { return lines_; }
  std::string output() const { return joined(lines_); }

 private:
  std::string echo_;
  std::optional<e2e::ChildProcess> child_;
  std::vector<std::string> lines_;
};

// What idlc of the bundle needs: its Python (the py backend) and its libraries.
std::vector<std::string> idlc_env() {
  const char* path = std::getenv("PATH");
  return {"PATH=" + (kPydds / "bin").string() + ":" + (path != nullptr ? path : "/usr/bin:/bin"),
          "LD_LIBRARY_PATH=" + (kPydds / "cyclonedds-c/lib").string()};
}

// The members of `struct NAME { ... };` in IDL text, ours or the generic
// tool's reconstruction: each declaration's name in order (an array's
// without its bounds), and those marked @key; nullopt without that struct.
struct Members {
  std::vector<std::string> names;
  std::vector<std::string> keys;
  bool final = false;  // @final on the line before it
};
std::string trimmed(std::string s) {
  if (const auto c = s.find("//"); c != std::string::npos) s.erase(c);
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}
std::optional<Members> struct_members(const std::string& idl, const std::string& name) {
  std::istringstream in(idl);
  std::string line, previous;
  while (std::getline(in, line)) {
    line = trimmed(line);
    if (line == "struct " + name + " {") break;
    if (!line.empty()) previous = line;
  }
  if (!in) return std::nullopt;
  Members m;
  m.final = previous == "@final";
  while (std::getline(in, line)) {
    line = trimmed(line);
    if (line == "};") return m;
    if (line.empty() || line.back() != ';') continue;
    line.pop_back();
    std::string member = line.substr(line.find_last_of(" \t") + 1);
    member = member.substr(0, member.find('['));
    m.names.push_back(member);
    if (line.rfind("@key", 0) == 0) m.keys.push_back(member);
  }
  return std::nullopt;
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cyclone11InteropTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // /tmp/pydds is the bundle (unpacked if it was not).
    Program bundle({"/bin/bash", DNBRIDGE_SOURCE_DIR "/tests/interop/cyclone11_bundle.sh",
                    DNBRIDGE_CYCLONE11_BUNDLE},
                   {}, "cyclone11_bundle.sh| ");
    ASSERT_EQ(bundle.finish(kBundleBound), 0)
        << "no Cyclone DDS 11 at " << kPydds << " (" << DNBRIDGE_CYCLONE11_BUNDLE
        << "; its message above): " << bundle.output();

    char dir[] = "/tmp/dnbridge-cyclone11-XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    work_ = dir;
    std::ofstream(work_ / "rack.toml") << rack_config();
    bridge_.emplace(std::vector<std::string>{DNBRIDGE_BINARY, "-c", (work_ / "rack.toml").string()},
                    e2e::ChildOptions{{cyclonedds_uri()}, false, false});
    ASSERT_TRUE(bridge_->running());
  }

  // The bridge is stopped and must exit 0.
  void TearDown() override {
    if (bridge_) {
      EXPECT_TRUE(bridge_->signal(SIGTERM));
      EXPECT_EQ(bridge_->wait_for(kBridgeStop), 0) << "the bridge did not stop cleanly";
      bridge_.reset();
    }
    if (!work_.empty()) fs::remove_all(work_);
  }

  // The bundle's idlc makes the Python package `dnbridge` of `idl` in
  // work_/DIR (it writes where it runs); that directory, for PYTHONPATH.
  fs::path python_types(const std::string& idl, const std::string& dir) {
    const fs::path out = work_ / dir;
    fs::create_directories(out);
    Program idlc({"/usr/bin/env", "-C", out.string(), kIdlc.string(), "-l", "py", idl}, idlc_env());
    EXPECT_EQ(idlc.finish(kIdlcBound), 0) << "idlc -l py " << idl << " failed: " << idlc.output();
    EXPECT_TRUE(fs::exists(out / "dnbridge/__init__.py")) << "idlc made no package dnbridge";
    return out;
  }

  // `cyclonedds typeof dnbridge/TOPIC` of the bundle, started.
  static std::unique_ptr<Program> typeof_topic(const std::string& topic) {
    // Rich renders for a console this wide (not a terminal: no colours).
    return std::make_unique<Program>(
        std::vector<std::string>{kCli.string(), "typeof", "dnbridge/" + topic, "--id",
                                 std::to_string(kDomain), "--runtime", kTypeofScan,
                                 "--suppress-progress-bar", "--color", "none"},
        std::vector<std::string>{"COLUMNS=160"});
  }

  fs::path work_;
  std::optional<e2e::ChildProcess> bridge_;
};

TEST_F(Cyclone11InteropTest, ASupervisorReadsTheStateAndUsesEveryCommandAndRequestTopic) {
  const fs::path types = python_types(DNBRIDGE_SOURCE_DIR "/idl/dnbridge.idl", "types");
  ASSERT_FALSE(HasFailure());
  // Its steps as they pass (or the topic that failed), printed as they come.
  Program supervisor(
      {kPython.string(), "-u", kSupervisor.string(), "supervise", std::to_string(kDomain), kRack,
       kPort, std::to_string(kPump), std::to_string(kDevice), "cyclone11 supervisor"},
      {"PYTHONPATH=" + types.string()}, "cyclone11 supervisor| ");
  const auto started = Clock::now();
  EXPECT_EQ(supervisor.finish(kSupervisorBound), 0) << supervisor.output();
  ASSERT_FALSE(supervisor.lines().empty());
  EXPECT_EQ(supervisor.lines().back(), "supervisor: every step passed");
  std::printf("the Cyclone DDS 11 supervisor ended after %.1f s\n",
              std::chrono::duration<double>(Clock::now() - started).count());
}

TEST_F(Cyclone11InteropTest, TheGenericToolShowsEveryTopicsTypeAsTheIdlHasIt) {
  const std::string idl = text_of(DNBRIDGE_SOURCE_DIR "/idl/dnbridge.idl");
  // Every topic at once, each its own process; those that found no type
  // (the bridge has just started: not discovered yet) again, until the
  // bridge has been running for kBridgeFound.
  const auto deadline = Clock::now() + kBridgeFound;
  std::vector<std::string> shown(kTopics.size());
  std::vector<std::size_t> pending(kTopics.size());
  for (std::size_t i = 0; i < kTopics.size(); ++i) pending[i] = i;
  while (!pending.empty()) {
    std::vector<std::unique_ptr<Program>> tools;
    for (const auto i : pending) tools.push_back(typeof_topic(kTopics[i]));
    std::vector<std::size_t> again;
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const std::size_t i = pending[t];
      ASSERT_EQ(tools[t]->finish(kTypeofBound), 0)
          << "cyclonedds typeof dnbridge/" << kTopics[i] << ":\n"
          << tools[t]->output();
      shown[i] = tools[t]->output();
      if (shown[i].find("No types could be discovered") != std::string::npos) again.push_back(i);
    }
    if (again.empty() || Clock::now() > deadline) break;
    std::printf("typeof found no type of %zu topic(s) yet: again\n", again.size());
    pending = std::move(again);
  }
  for (std::size_t i = 0; i < kTopics.size(); ++i) {
    const std::string& topic = kTopics[i];
    SCOPED_TRACE("cyclonedds typeof dnbridge/" + topic + ":\n" + shown[i]);
    const auto expected = struct_members(idl, topic);
    ASSERT_TRUE(expected) << "idl/dnbridge.idl has no struct " << topic;
    const auto seen = struct_members(shown[i], topic);
    ASSERT_TRUE(seen) << "dnbridge/" << topic << ": no struct " << topic << " shown";
    EXPECT_NE(shown[i].find("module dnbridge {"), std::string::npos);
    EXPECT_EQ(shown[i].find("Multiple type definitions"), std::string::npos);
    EXPECT_TRUE(seen->final) << topic << " not shown @final";
    EXPECT_EQ(seen->names, expected->names) << topic << ": not the IDL's members";
    EXPECT_EQ(seen->keys, expected->keys) << topic << ": not the IDL's keys";
  }
}

TEST_F(Cyclone11InteropTest, AReaderOfTheFormerNodeStatusIsNotMatched) {
  // NodeStatus as it was before its safe state became members of its own
  // (a nested struct of enums): its reader must get nothing, rather than
  // samples misread.
  const fs::path former =
      python_types(DNBRIDGE_SOURCE_DIR "/tests/interop/former_node_status.idl", "former");
  ASSERT_FALSE(HasFailure());
  // The bridge's side is not silent: PortStatus counts the reader, read here
  // with the bridge's own types and QoS.
  const std::string uri = cyclonedds_uri();
  ASSERT_EQ(setenv("CYCLONEDDS_URI", uri.substr(uri.find('=') + 1).c_str(), 1), 0);
  dds::Participant participant(kDomain, dds::Participant::ClientName{"cyclone11 interop test"});
  dds::Topic<dnbridge_PortStatus> topic(participant);
  dds::Reader<dnbridge_PortStatus> ports(participant, topic, dds::state_reader_qos());
  ASSERT_TRUE(ports.set_status_mask(DDS_DATA_AVAILABLE_STATUS));
  dds::WaitSet arrivals(participant);
  arrivals.attach(ports, 1);
  Program reader(
      {kPython.string(), "-u", kSupervisor.string(), "former-node-status", std::to_string(kDomain)},
      {"PYTHONPATH=" + former.string()}, "cyclone11 former NodeStatus| ");
  std::uint32_t unmatched = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (unmatched == 0 && std::chrono::steady_clock::now() < until) {
    auto taken = ports.take(16);
    ASSERT_TRUE(taken.ok());
    for (const auto& s : *taken) {
      if (s.valid_data()) unmatched = std::max(unmatched, s.data().endpoints_unmatched);
    }
    if (unmatched == 0) (void)arrivals.wait(std::chrono::seconds(1));
  }
  EXPECT_GE(unmatched, 1u) << "the bridge's PortStatus does not count the reader it does not match";
  EXPECT_EQ(reader.finish(kSupervisorBound), 0) << reader.output();
}

}  // namespace
}  // namespace dnbridge::interop_test
