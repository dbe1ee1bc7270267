// dnbridge on a real Linux CAN stack: the bridge, cdn127-sim and a DDS
// supervisor as separate processes on vcan interfaces of a kernel of their
// own. run_in_vm.sh runs each test in User-Mode Linux or QEMU.
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>
#include <utility>

#include "adapters/dnbctl/commander.hpp"
#include "system_fixture.hpp"

namespace dnbridge::system_test {
namespace {

using namespace std::chrono_literals;

std::string tail(const fs::path& file, std::size_t lines = 60) {
  std::ifstream in(file);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) {
    out += all[i] + "\n";
  }
  return out;
}

std::string run_output(const std::string& command) {
  std::string out;
  if (std::FILE* p = ::popen(command.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    ::pclose(p);
  }
  return out;
}

std::size_t count_lines(const fs::path& file, const std::string& containing) {
  std::ifstream in(file);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) n += l.find(containing) != std::string::npos;
  return n;
}

// One device's outputs and poll connection, as cdn127-sim's `status` shows them.
struct SimDevice {
  bool poll_established = false;
  bool pump_on = false;
  bool n2_ballast_on = false;
  unsigned aout = 0;
};
using SimStatus = std::map<unsigned, SimDevice>;

class SystemTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(socketcan::link_state("vcan0"), socketcan::LinkState::kUp)
        << "vcan0 is not up: the system tests run inside a virtual machine (ctest runs them "
           "through tests/system/run_in_vm.sh)";
    dir_ = work_dir();
    rack_ = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  }

  void TearDown() override {
    for (auto& c : children_) (void)c->stop();
    if (HasFailure()) {
      if (supervisor_) {
        supervisor_->update();
        std::printf("--- what the supervisor saw last\n%s", supervisor_->describe().c_str());
      }
      for (auto& c : children_) {
        std::printf("--- %s (last lines)\n%s", c->log().c_str(), tail(c->log()).c_str());
      }
    }
  }

  Child& start_bridge(const std::vector<PortSpec>& ports) {
    const fs::path config = dir_ / "rack.toml";
    std::ofstream(config) << rack_config(rack_, ports);
    children_.push_back(
        std::make_unique<Child>(std::vector<std::string>{DNBRIDGE_BIN, "--config", config.string(),
                                                         "--candump-dir", dir_.string()},
                                dir_ / "dnbridge.log"));
    return *children_.back();
  }

  Child& start_sim(const std::string& interface, const std::vector<unsigned>& macs,
                   const std::vector<std::string>& options = {}) {
    std::vector<std::string> argv{CDN127_SIM_BIN, "--iface", interface};
    for (auto m : macs) {
      argv.push_back("--mac");
      argv.push_back(std::to_string(m));
    }
    argv.insert(argv.end(), options.begin(), options.end());
    children_.push_back(
        std::make_unique<Child>(argv, dir_ / fmt::format("cdn127-sim-{}.log", interface)));
    return *children_.back();
  }

  // dnbctl commanding a pump on, and holding it on until killed.
  Child& start_commander(const std::string& port, unsigned mac) {
    const double timeout = static_cast<double>(patience(10000ms).count()) / 1000.0;
    children_.push_back(std::make_unique<Child>(
        std::vector<std::string>{DNBCTL_BIN, "--rack", rack_, "--port", port, "--timeout",
                                 fmt::format("{:g}", timeout), "pump", std::to_string(mac), "on",
                                 "--issuer", fmt::format("commander {}", mac), "--hold-for",
                                 "3600"},
        dir_ / fmt::format("dnbctl-{}.log", mac)));
    return *children_.back();
  }

  // cdn127-sim's answer to `status`, read from its log, for `devices`
  // devices; empty if no whole answer came within the test's patience.
  SimStatus sim_status(Child& sim, std::size_t devices) {
    static const std::regex line(
        R"(^ok mac (\d+) .* poll (\S+) \| outputs pump-on (on|off) n2-ballast (on|off) aout (\d+) )");
    const auto from = static_cast<std::streamoff>(fs::file_size(sim.log()));
    sim.send("status");
    const auto until = std::chrono::steady_clock::now() + patience(2000ms);
    for (;;) {
      SimStatus status;
      std::ifstream in(sim.log());
      in.seekg(from);
      std::smatch m;
      for (std::string l; std::getline(in, l);) {
        if (!std::regex_search(l, m, line)) continue;
        status[static_cast<unsigned>(std::stoul(m[1]))] =
            SimDevice{m[2] == "established", m[3] == "on", m[4] == "on",
                      static_cast<unsigned>(std::stoul(m[5]))};
      }
      if (status.size() == devices) return status;
      if (std::chrono::steady_clock::now() >= until) return {};
      std::this_thread::sleep_for(2ms);
    }
  }

  // Reads cdn127-sim's status until `done` holds for it or `timeout` (scaled
  // by patience) has passed; whether it held.
  bool wait_sim(Child& sim, std::size_t devices, const std::function<bool(const SimStatus&)>& done,
                std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + patience(timeout);
    for (;;) {
      const SimStatus s = sim_status(sim, devices);
      if (!s.empty() && done(s)) return true;
      if (std::chrono::steady_clock::now() >= until) return false;
      std::this_thread::sleep_for(20ms);
    }
  }

  // For each of `macs`, how long after `since` cdn127-sim's status first
  // showed `reached` for its device, with that status; reads it every 10 ms
  // until each has or `timeout` (scaled by patience) has passed.
  std::map<unsigned, std::pair<std::chrono::milliseconds, SimDevice>> time_until(
      Child& sim, std::size_t devices, const std::vector<unsigned>& macs,
      const std::function<bool(const SimDevice&)>& reached,
      std::chrono::steady_clock::time_point since, std::chrono::milliseconds timeout) {
    std::map<unsigned, std::pair<std::chrono::milliseconds, SimDevice>> out;
    const auto until = std::chrono::steady_clock::now() + patience(timeout);
    while (out.size() < macs.size() && std::chrono::steady_clock::now() < until) {
      const SimStatus s = sim_status(sim, devices);
      const auto after = std::chrono::duration_cast<std::chrono::milliseconds>(
          std::chrono::steady_clock::now() - since);
      for (unsigned mac : macs) {
        auto it = s.find(mac);
        if (!out.contains(mac) && it != s.end() && reached(it->second)) {
          out[mac] = {after, it->second};
        }
      }
      std::this_thread::sleep_for(10ms);
    }
    return out;
  }

  Supervisor& supervisor() {
    if (!supervisor_) supervisor_ = std::make_unique<Supervisor>(rack_);
    return *supervisor_;
  }

  bool wait_online(const std::string& port, const std::vector<unsigned>& macs,
                   std::chrono::seconds timeout = 30s) {
    return supervisor().wait_until([&] { return supervisor().all_online(port, macs); }, timeout);
  }
  bool wait_offline(const std::string& port, unsigned mac, std::chrono::seconds timeout = 15s) {
    return supervisor().wait_until([&] { return !supervisor().online(port, mac); }, timeout);
  }
  const PumpSeen& pump(const std::string& port, unsigned mac) {
    return supervisor().pumps().at(PumpKey{port, mac});
  }
  bool port_bus(const std::string& port, dnbridge_BusState state) {
    auto it = supervisor().ports().find(port);
    return it != supervisor().ports().end() && it->second.bus_state == state;
  }

  // Wireshark's DeviceNet dissector on a whole capture: every frame taken
  // as DeviceNet, none marked malformed or invalid.
  void expect_clean_under_tshark(const fs::path& pcap, std::uint64_t frames) {
    ASSERT_GT(frames, 100u) << "too little traffic captured";
    const std::string tshark = DNBRIDGE_TSHARK;
    ASSERT_FALSE(tshark.empty()) << "tshark not found at configure time (bash .ci/deps)";
    const std::string base =
        fmt::format("'{}' -n -r '{}' -d can.subdissector,devicenet", tshark, pcap.string());
    const std::string decoded =
        run_output(base + " -Y devicenet -T fields -e frame.number 2>/dev/null | wc -l");
    EXPECT_EQ(std::stoull(decoded), frames) << "frames the dissector did not take as DeviceNet";
    const std::string bad = run_output(
        base +
        " -Y '_ws.malformed || _ws.expert.severity >= \"warning\"' -T fields -e frame.number "
        "-e can.id -e _ws.expert.message 2>/dev/null");
    EXPECT_TRUE(bad.empty()) << "frames marked malformed or invalid (frame, id, message):\n"
                             << bad << "capture kept: " << pcap;
    std::printf("captured %llu frames, all decoded as DeviceNet without a warning\n",
                static_cast<unsigned long long>(frames));
  }

  fs::path dir_;
  std::string rack_;
  std::vector<std::unique_ptr<Child>> children_;
  std::unique_ptr<Supervisor> supervisor_;
};

// A rack of three CDN127s: online, inputs and commands round-trip through
// DDS, and every frame of the run decodes cleanly in Wireshark's DeviceNet
// dissector.
TEST_F(SystemTest, RackOnlineStateAndCommandsOnTheWire) {
  const fs::path pcap = dir_ / "vcan0.pcap";
  auto capture = std::make_unique<Capture>("vcan0", pcap);
  Child& sim = start_sim("vcan0", {5, 6, 7});
  Child& bridge = start_bridge({{"A", "vcan0", {5, 6, 7}}});

  ASSERT_TRUE(wait_online("A", {5, 6, 7})) << "not every node came online";
  ASSERT_TRUE(supervisor().wait_until(
      [&] {
        auto it = supervisor().ports().find("A");
        return it != supervisor().ports().end() && it->second.nodes_online == 3;
      },
      10s));
  const PortSeen& port = supervisor().ports().at("A");
  EXPECT_EQ(port.can_interface, "vcan0");
  EXPECT_EQ(port.state, dnbridge_PORT_RUNNING);
  EXPECT_EQ(port.bus_state, dnbridge_BUS_STATE_UNKNOWN) << "vcan reports no controller state";

  // Source timestamps are the kernel's receive times: just before arrival.
  for (unsigned mac : {5u, 6u, 7u}) {
    const PumpSeen& p = pump("A", mac);
    EXPECT_LE(p.source_time, p.received + 100ms) << "MAC " << mac;
    EXPECT_LT(p.received - p.source_time, 5s) << "MAC " << mac;
  }

  // A command to pump 5: the output is applied, and the pump spins up.
  ASSERT_TRUE(supervisor().command("A", 5, true));
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("A", 5).pump_on; }, 10s));
  EXPECT_EQ(pump("A", 5).commanded_by, "system-test");
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("A", 5).pump_running; }, 15s))
      << "the pump did not report running after its spin-up";

  // Inputs driven at the simulator reach the supervisor.
  sim.send("set 6 alarm on");
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("A", 6).alarm_active; }, 10s));
  sim.send("set 7 ain1 2.5V");
  ASSERT_TRUE(supervisor().wait_until(
      [&] { return std::fabs(pump("A", 7).analog_in1 - 2.5F) < 0.01F; }, 10s));
  sim.send("set 6 alarm off");
  ASSERT_TRUE(supervisor().wait_until([&] { return !pump("A", 6).alarm_active; }, 10s));
  EXPECT_TRUE(pump("A", 5).pump_running);

  // An orderly stop: every node idled and released, exit status 0.
  const int status = bridge.stop(10000ms);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "dnbridge status " << status;
  (void)sim.stop();
  const std::uint64_t frames = capture->stop();
  ASSERT_GT(frames, 100u) << "too little traffic captured";

  expect_clean_under_tshark(pcap, frames);
}

// cdn127-sim devices with every reading of the manual that field devices
// took (--reading field: configuration locked while a poll connection
// exists, fixed poll paths, idle polls answered empty, no ack of a
// request's last fragment, outputs kept on a Release, explicit answers
// 300 ms and poll answers 3 ms
// late, a 2-byte serial number, no Identity State, expected packet rates in
// steps of 100 ms): every node online with one allocation of each
// connection, a command applied, the whole traffic clean under tshark.
TEST_F(SystemTest, RackOnlineWithFieldReadingDevices) {
  const fs::path pcap = dir_ / "vcan0.pcap";
  auto capture = std::make_unique<Capture>("vcan0", pcap);
  start_sim("vcan0", {5, 6, 7}, {"--reading", "field"});
  Child& bridge = start_bridge({{"A", "vcan0", {5, 6, 7}}});
  ASSERT_TRUE(wait_online("A", {5, 6, 7})) << "not every node came online";
  ASSERT_TRUE(supervisor().command("A", 6, true));
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("A", 6).pump_on; }, 10s));
  // Idle polls answered empty keep the other two online: samples of all
  // three keep coming, online, for three seconds more (the bridge publishes
  // each pump at least once a second).
  const dds::Timestamp since = pump("A", 6).received;
  ASSERT_TRUE(supervisor().wait_until(
      [&] {
        for (unsigned mac : {5u, 6u, 7u}) {
          if (!pump("A", mac).online || pump("A", mac).received < since + 3s) return false;
        }
        return true;
      },
      10s));
  EXPECT_TRUE(pump("A", 6).pump_on);

  const int status = bridge.stop(10000ms);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "dnbridge status " << status;
  const std::uint64_t frames = capture->stop();
  // Allocate on Group 2 message 6: [hdr][4B][03][01][choice][master MAC].
  for (unsigned mac : {5u, 6u, 7u}) {
    unsigned explicit_allocations = 0, poll_allocations = 0;
    for (const can::CanFrame& f : capture->frames()) {
      if (f.id != 0x406u + (mac << 3) || f.len != 6 || f.data[1] != 0x4B) continue;
      explicit_allocations += f.data[4] == 0x01;
      poll_allocations += f.data[4] == 0x02;
    }
    EXPECT_EQ(explicit_allocations, 1u) << "MAC " << mac;
    EXPECT_EQ(poll_allocations, 1u) << "MAC " << mac;
  }
  expect_clean_under_tshark(pcap, frames);
}

// A CDN127 and two devices driven by their EDS files, all simulated by
// cdn127-sim on one bus: the example I/O block on change of state, without
// member lists (the start-up check tolerates it), and the example valve
// manifold on bit-strobe. All online; the I/O block's connection 4
// allocated (choice 0x10) beside its poll connection, a change of its
// inputs produced at once and every message acknowledged by the bridge; the
// manifold's connection 3 allocated (choice 0x04), the bridge's bit-strobe
// commands answered one by one (through the SocketCAN receive filter); the
// counters in NodeStatus (dnbctl show), the pump commanded
// as ever, and the whole traffic clean under tshark.
TEST_F(SystemTest, ACdn127AndEdsDevicesOnChangeOfStateAndBitStrobeShareABus) {
  constexpr unsigned kPump = 1, kIo = 21, kValves = 22;
  const fs::path pcap = dir_ / "vcan0.pcap";
  auto capture = std::make_unique<Capture>("vcan0", pcap);
  const fs::path devices = dir_ / "devices.toml";
  std::ofstream(devices) << fmt::format(
      "[[device]]\nmac = {}\neds = \"{}/dnbridge-example-io-block.eds\"\nmember_lists = false\n"
      "[[device]]\nmac = {}\neds = \"{}/dnbridge-example-valve-manifold.eds\"\n",
      kIo, DNBRIDGE_EDS_DIR, kValves, DNBRIDGE_EDS_DIR);
  Child& sim = start_sim("vcan0", {kPump}, {"--device-config", devices.string()});
  const std::string io_node = fmt::format(
      "  profile = \"eds\"\n  eds = \"{}/dnbridge-example-io-block.eds\"\n"
      "  connection = \"change-of-state\"\n  heartbeat_ms = 200\n  inhibit_ms = 10\n"
      "  safe_state_parameters = [ {{ name = \"Output fault action\", value = 0 }},\n"
      "    {{ name = \"Output fault value\", value = 0 }},\n"
      "    {{ name = \"Output idle action\", value = 0 }},\n"
      "    {{ name = \"Output idle value\", value = 0 }} ]",
      DNBRIDGE_EDS_DIR);
  const std::string valves_node = fmt::format(
      "  profile = \"eds\"\n  eds = \"{}/dnbridge-example-valve-manifold.eds\"\n"
      "  connection = \"bit-strobe\"\n"
      "  safe_state_parameters = [ {{ name = \"Output fault action\", value = 0 }},\n"
      "    {{ name = \"Output fault value\", value = 0 }},\n"
      "    {{ name = \"Output idle action\", value = 0 }},\n"
      "    {{ name = \"Output idle value\", value = 0 }} ]",
      DNBRIDGE_EDS_DIR);
  Child& bridge = start_bridge(
      {{"A", "vcan0", {kPump, kIo, kValves}, {{kIo, io_node}, {kValves, valves_node}}}});
  ASSERT_TRUE(wait_online("A", {kPump})) << "the pump did not come online";

  // The devices, as cdn127-sim shows them: owned, their connections
  // established.
  static const std::regex eds_line(
      R"(^ok mac (\d+) power on network online owner (\d+) poll (\S+) cos (\S+) \| eds .* \| )"
      R"(inputs (\S+) outputs \S+ \| cos produced (\d+) acks (\d+) retries \d+ )"
      R"(given-up \d+ late (\d+) \| strobe (\S+) commands (\d+) responses (\d+))");
  struct EdsSeen {
    bool established = false;  // poll and change of state, or poll and bit-strobe
    std::string inputs;
    unsigned long produced = 0, acks = 0, late = 0;
    unsigned long strobes = 0, strobe_responses = 0;
  };
  const auto eds_status = [&](unsigned mac) {
    EdsSeen seen;
    const auto from = static_cast<std::streamoff>(fs::file_size(sim.log()));
    sim.send(fmt::format("status {}", mac));
    const auto until = std::chrono::steady_clock::now() + patience(2000ms);
    while (std::chrono::steady_clock::now() < until) {
      std::ifstream in(sim.log());
      in.seekg(from);
      std::smatch m;
      for (std::string l; std::getline(in, l);) {
        if (!std::regex_search(l, m, eds_line) || std::stoul(m[1]) != mac) continue;
        seen.established = m[3] == "established" && (mac == kIo ? m[4] : m[9]) == "established";
        seen.inputs = m[5];
        seen.produced = std::stoul(m[6]);
        seen.acks = std::stoul(m[7]);
        seen.late = std::stoul(m[8]);
        seen.strobes = std::stoul(m[10]);
        seen.strobe_responses = std::stoul(m[11]);
        return seen;
      }
      std::this_thread::sleep_for(5ms);
    }
    return seen;
  };
  const auto until = [&](const std::function<bool(const EdsSeen&)>& done,
                         std::chrono::milliseconds timeout, unsigned mac) {
    const auto end = std::chrono::steady_clock::now() + patience(timeout);
    while (std::chrono::steady_clock::now() < end) {
      if (done(eds_status(mac))) return true;
      std::this_thread::sleep_for(50ms);
    }
    return false;
  };
  ASSERT_TRUE(until([](const EdsSeen& s) { return s.established; }, 20000ms, kIo))
      << "the EDS device's connections were not established";
  // The valve manifold: strobed every 100 ms (its poll period), each
  // command answered.
  ASSERT_TRUE(until([](const EdsSeen& s) { return s.established && s.strobe_responses >= 10; },
                    20000ms, kValves))
      << "the valve manifold's bit-strobe connection did not answer";

  // Its digital inputs change: produced at once, acknowledged; heartbeats
  // every 200 ms meanwhile. `produced` counts every transmission, and the
  // bridge acknowledges each: one whose acknowledgment came after the
  // device's ack timeout (20 ms: a host busy under User-Mode Linux) was sent
  // again, and acknowledged too; an acknowledgment that came when none was
  // waiting (after the retry) is counted late. Each is acknowledged, in time
  // or not.
  sim.send(fmt::format("set {} param 3 90", kIo));
  ASSERT_TRUE(until([](const EdsSeen& s) { return s.inputs.rfind("5A", 0) == 0; }, 5000ms, kIo));
  ASSERT_TRUE(
      until([](const EdsSeen& s) { return s.produced >= 5 && s.acks + s.late >= s.produced; },
            5000ms, kIo))
      << "not every change-of-state message was acknowledged";

  // What the bridge counted, as dnbctl shows it.
  const std::string shown = run_output(fmt::format(
      "'{}' --rack '{}' --port A --timeout 10 show {} --json 2>&1", DNBCTL_BIN, rack_, kIo));
  std::smatch m;
  ASSERT_TRUE(std::regex_search(shown, m, std::regex(R"("cos_acks":\s*(\d+))"))) << shown;
  EXPECT_GE(std::stoul(m[1]), 5u) << shown;
  EXPECT_NE(shown.find("inputs on change of state (EPR 200 ms, acknowledged"), std::string::npos)
      << shown;
  const std::string valves = run_output(fmt::format(
      "'{}' --rack '{}' --port A --timeout 10 show {} --json 2>&1", DNBCTL_BIN, rack_, kValves));
  EXPECT_NE(valves.find("inputs bit-strobed"), std::string::npos) << valves;
  ASSERT_TRUE(std::regex_search(valves, m, std::regex(R"("cos_messages":\s*(\d+))"))) << valves;
  EXPECT_GE(std::stoul(m[1]), 10u) << valves;

  // The pump is commanded as ever.
  ASSERT_TRUE(supervisor().command("A", kPump, true));
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("A", kPump).pump_on; }, 10s));

  const int status = bridge.stop(10000ms);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "dnbridge status " << status;
  (void)sim.stop();
  const std::uint64_t frames = capture->stop();
  // Its member lists refused (0x14), not compared: logged, and no fault.
  EXPECT_EQ(count_lines(bridge.log(),
                        "Assembly 100 member list (Assem100 Inputs and status) not "
                        "offered (attribute not supported (0x14/0xFF)): not compared"),
            1u);
  // On the wire: Allocate of connection 4 (choice 0x10) to MAC 21 once, its
  // messages on Group 1 message 13 and the bridge's acknowledgments on
  // Group 2 message 2, each after the message it acknowledges.
  // The bit-strobe commands of the bridge (master MAC 0: Group 2 message
  // 0, 0x400), 8 bytes of 0, each answered by the manifold on Group 1
  // message 14, each answer after its command (under User-Mode Linux an
  // answer may come after the next command).
  unsigned cos_allocations = 0, messages = 0, acks = 0, acks_without_message = 0;
  unsigned strobe_allocations = 0, strobes = 0, odd_strobes = 0, responses = 0,
           responses_without_strobe = 0;
  bool change_seen = false;
  for (const can::CanFrame& f : capture->frames()) {
    if (f.id == 0x406u + (kValves << 3) && f.len == 6 && f.data[1] == 0x4B) {
      strobe_allocations += f.data[4] == 0x04;
    } else if (f.id == 0x400u) {
      ++strobes;
      odd_strobes += f.len != 8 || std::any_of(f.data.begin(), f.data.end(),
                                               [](std::uint8_t b) { return b != 0; });
    } else if (f.id == 0x380u + kValves) {
      ++responses;
      responses_without_strobe += responses > strobes;
    } else if (f.id == 0x406u + (kIo << 3) && f.len == 6 && f.data[1] == 0x4B) {
      cos_allocations += f.data[4] == 0x10;
    } else if (f.id == 0x340u + kIo) {
      ++messages;
      change_seen = change_seen || (f.len == 4 && f.data[0] == 0x5A);
    } else if (f.id == 0x402u + (kIo << 3)) {
      ++acks;
      acks_without_message += acks > messages;
    }
  }
  EXPECT_EQ(cos_allocations, 1u);
  EXPECT_TRUE(change_seen);
  EXPECT_GE(messages, 5u);
  EXPECT_GE(acks + 1, messages);  // the last may have gone with the stop
  EXPECT_EQ(acks_without_message, 0u);
  EXPECT_EQ(strobe_allocations, 1u);
  EXPECT_GE(strobes, 10u);
  EXPECT_EQ(odd_strobes, 0u);
  EXPECT_EQ(responses_without_strobe, 0u);
  EXPECT_GE(responses + 1, strobes);  // the last may have gone with the stop
  expect_clean_under_tshark(pcap, frames);
}

// One bridge, two ports, each on its own interface and bus.
TEST_F(SystemTest, TwoPortsServedByOneBridge) {
  start_sim("vcan0", {5, 6});
  start_sim("vcan1", {10, 11});
  Child& bridge = start_bridge({{"A", "vcan0", {5, 6}}, {"B", "vcan1", {10, 11}}});
  ASSERT_TRUE(wait_online("A", {5, 6}));
  ASSERT_TRUE(wait_online("B", {10, 11}));
  ASSERT_TRUE(supervisor().command("B", 10, true));
  ASSERT_TRUE(supervisor().wait_until([&] { return pump("B", 10).pump_on; }, 10s));
  EXPECT_FALSE(pump("A", 5).pump_on) << "a command for port B reached port A";
  EXPECT_EQ(supervisor().ports().at("A").can_interface, "vcan0");
  EXPECT_EQ(supervisor().ports().at("B").can_interface, "vcan1");
  EXPECT_TRUE(bridge.running());

  // SIGUSR1: a candump -l log per port, for field diagnosis, until the next.
  bridge.signal(SIGUSR1);
  const fs::path log_a = dir_ / "dnbridge-A-candump.log";
  const fs::path log_b = dir_ / "dnbridge-B-candump.log";
  ASSERT_TRUE(supervisor().wait_until(
      [&] { return count_lines(log_a, " vcan0 ") > 20 && count_lines(log_b, " vcan1 ") > 20; },
      10s))
      << "no candump log after SIGUSR1";
  bridge.signal(SIGUSR1);
  const auto settled = [&] {
    const auto a = count_lines(log_a, " vcan0 ");
    std::this_thread::sleep_for(300ms);
    return count_lines(log_a, " vcan0 ") == a;
  };
  ASSERT_TRUE(supervisor().wait_until(settled, 5s)) << "the second SIGUSR1 did not stop the log";
  // A line as candump -l writes it: "(1700000000.123456) vcan0 3C5#..."
  std::ifstream in(log_a);
  std::string line;
  std::getline(in, line);
  EXPECT_TRUE(
      std::regex_match(line, std::regex(R"(\(\d+\.\d{6}\) vcan0 [0-9A-F]{3}#([0-9A-F]{2})*)")))
      << line;
}

// The interface goes down and comes back, then is removed and created again:
// the port reports it, and the nodes come back by themselves, without a
// restart of any process.
TEST_F(SystemTest, InterfaceDownAndUpWhileRunning) {
  Child& sim = start_sim("vcan0", {5, 6});
  Child& bridge = start_bridge({{"A", "vcan0", {5, 6}}});
  ASSERT_TRUE(wait_online("A", {5, 6}));

  ASSERT_EQ(shell("ip link set down vcan0"), 0);
  ASSERT_TRUE(supervisor().wait_until([&] { return port_bus("A", dnbridge_BUS_DOWN); }, 10s))
      << "the port did not report the interface down";
  EXPECT_NE(supervisor().ports().at("A").reason.find("vcan0"), std::string::npos)
      << supervisor().ports().at("A").reason;
  ASSERT_TRUE(wait_offline("A", 5));
  ASSERT_TRUE(wait_offline("A", 6));
  ASSERT_EQ(shell("ip link set up vcan0"), 0);
  ASSERT_TRUE(wait_online("A", {5, 6})) << "the nodes did not come back after the interface did";
  EXPECT_FALSE(port_bus("A", dnbridge_BUS_DOWN));

  // Removed and created again: a new interface index, a new socket.
  ASSERT_EQ(shell("ip link del dev vcan0"), 0);
  ASSERT_TRUE(supervisor().wait_until([&] { return port_bus("A", dnbridge_BUS_DOWN); }, 10s));
  ASSERT_TRUE(wait_offline("A", 5));
  ASSERT_EQ(shell("ip link add dev vcan0 type vcan && ip link set up vcan0"), 0);
  ASSERT_TRUE(wait_online("A", {5, 6})) << "the nodes did not come back on the new interface";

  EXPECT_TRUE(bridge.running()) << "dnbridge exited";
  EXPECT_TRUE(sim.running()) << "cdn127-sim exited";
}

// A port whose interface does not exist when dnbridge starts: the port says
// so and waits, its master silent (no MAC check into the void), while the
// other port runs; once the interface is created its master starts and the
// nodes come online, without a restart.
TEST_F(SystemTest, InterfaceAbsentAtStartIsWaitedFor) {
  ASSERT_EQ(shell("ip link del dev vcan1"), 0);
  Child& sim0 = start_sim("vcan0", {5});
  Child& bridge = start_bridge({{"A", "vcan0", {5}}, {"B", "vcan1", {7}}});
  ASSERT_TRUE(wait_online("A", {5}));
  ASSERT_TRUE(supervisor().wait_until([&] { return port_bus("B", dnbridge_BUS_DOWN); }, 10s));
  {
    const PortSeen& b = supervisor().ports().at("B");
    EXPECT_EQ(b.state, dnbridge_PORT_STOPPED);
    EXPECT_NE(b.reason.find("interface vcan1 absent"), std::string::npos) << b.reason;
    EXPECT_NE(b.reason.find("waiting for the interface"), std::string::npos) << b.reason;
  }

  ASSERT_EQ(shell("ip link add dev vcan1 type vcan && ip link set up vcan1"), 0);
  start_sim("vcan1", {7});
  ASSERT_TRUE(wait_online("B", {7})) << "port B did not start once its interface was there";
  EXPECT_FALSE(port_bus("B", dnbridge_BUS_DOWN));
  EXPECT_TRUE(pump("A", 5).online);
  EXPECT_TRUE(bridge.running()) << "dnbridge exited";
  EXPECT_TRUE(sim0.running()) << "cdn127-sim exited";
}

// A simulated device power-cycled (and powered off and on) under cdn127-sim
// comes back online by itself.
TEST_F(SystemTest, PowerCycledDeviceComesBack) {
  Child& sim = start_sim("vcan0", {5, 6});
  start_bridge({{"A", "vcan0", {5, 6}}});
  ASSERT_TRUE(wait_online("A", {5, 6}));
  ASSERT_TRUE(supervisor().command("A", 6, true));
  ASSERT_TRUE(wait_sim(
      sim, 2, [](const SimStatus& s) { return s.at(6).pump_on; }, 10s))
      << "pump 6 did not come on";

  sim.send("power-cycle 6");
  ASSERT_TRUE(wait_offline("A", 6)) << "the master did not notice the power cycle";
  ASSERT_TRUE(wait_online("A", {5, 6})) << "node 6 did not come back after its power cycle";
  // Back idle: the command from before the power cycle is not applied again.
  ASSERT_TRUE(supervisor().wait_until(
      [&] {
        return pump("A", 6).online && pump("A", 6).outputs_idle &&
               pump("A", 6).idle_reason == "idle: waiting for a new command after reconnection";
      },
      10s))
      << "node 6: " << pump("A", 6).idle_reason;
  {
    const SimStatus s = sim_status(sim, 2);
    ASSERT_FALSE(s.empty()) << "no status from cdn127-sim";
    EXPECT_FALSE(s.at(6).pump_on) << "pump 6 came back on by itself";
    EXPECT_TRUE(s.at(6).poll_established);
  }
  // A command written after the return: applied.
  ASSERT_TRUE(supervisor().command("A", 6, true));
  ASSERT_TRUE(wait_sim(
      sim, 2, [](const SimStatus& s) { return s.at(6).pump_on; }, 10s))
      << "pump 6 did not come on after a new command";

  sim.send("power-off 5");
  ASSERT_TRUE(wait_offline("A", 5));
  EXPECT_TRUE(supervisor().online("A", 6));
  sim.send("power-on 5");
  ASSERT_TRUE(wait_online("A", {5, 6})) << "node 5 did not come back after power-on";
}

// CDN127s whose factory fault and idle actions hold every output (a pump
// that is on stays on when its master goes idle or away) are made safe by
// the safe state the bridge downloads before polling them (the default:
// outputs off on fault and on idle, analog output 0 V). When the commander
// dies, the pumps stop within its liveliness lease plus one poll (idle); when
// the bridge dies (SIGKILL: no idle poll, no Release), within 4 x EPR (the
// devices' fault action). Node 7 keeps the device's own actions
// (safe_state = "device"): the control that shows the factory state unsafe
// over the wire, and that this test sees a pump left on.
TEST_F(SystemTest, UnsafeFactoryDevicesAreMadeSafeByTheBridge) {
  const std::vector<unsigned> all{5, 6, 7};
  const std::vector<unsigned> configured{5, 6};
  constexpr unsigned kControl = 7;
  // What the test adds to the bounds for its own observation: DDS and the
  // status round trip inside the virtual machine; scaled by patience.
  constexpr auto kObservation = 250ms;
  const fs::path devices = dir_ / "devices.toml";
  std::ofstream(devices) << "[defaults]\nunsafe_factory_output_actions = true\n";
  Child& sim = start_sim("vcan0", all, {"--device-config", devices.string()});
  Child& bridge = start_bridge({{"A", "vcan0", all, {{kControl, "safe_state = \"device\""}}}});
  ASSERT_TRUE(wait_online("A", all));

  // A commander of each pump: dnbctl, pump on, holding.
  std::vector<Child*> commanders;
  for (unsigned mac : all) commanders.push_back(&start_commander("A", mac));
  const auto all_on = [&](const SimStatus& s) {
    return std::all_of(all.begin(), all.end(), [&](unsigned m) { return s.at(m).pump_on; });
  };
  ASSERT_TRUE(wait_sim(sim, all.size(), all_on, 20s)) << "the pumps did not come on";
  ASSERT_TRUE(supervisor().wait_until(
      [&] {
        return std::all_of(all.begin(), all.end(), [&](unsigned m) {
          return pump("A", m).pump_on && !pump("A", m).outputs_idle &&
                 pump("A", m).commanded_by == fmt::format("commander {}", m);
        });
      },
      10s));

  // The commanders die: once their lease is over, the bridge polls idle.
  using std::chrono::milliseconds;
  const auto lease = std::chrono::duration_cast<milliseconds>(dnbctl::kCommandLease);
  const milliseconds idle_bound = lease + kPollPeriod + patience(kObservation);
  const auto left = std::chrono::steady_clock::now();
  for (Child* c : commanders) c->signal(SIGKILL);
  const auto stopped = time_until(
      sim, all.size(), configured, [](const SimDevice& d) { return !d.pump_on; }, left,
      idle_bound + 5s);
  for (unsigned mac : configured) {
    ASSERT_TRUE(stopped.contains(mac)) << "pump " << mac << " still on after the commander left";
    const auto& [after, d] = stopped.at(mac);
    std::printf(
        "pump %u off %lld ms after its commander was killed (lease %lld ms + poll %lld ms)\n", mac,
        static_cast<long long>(after.count()), static_cast<long long>(lease.count()),
        static_cast<long long>(kPollPeriod.count()));
    EXPECT_LE(after.count(), idle_bound.count()) << "pump " << mac;
    EXPECT_TRUE(d.poll_established) << "pump " << mac << ": its poll connection ended";
  }
  ASSERT_TRUE(supervisor().wait_until(
      [&] {
        return std::all_of(all.begin(), all.end(), [&](unsigned m) {
          return pump("A", m).online && pump("A", m).outputs_idle;
        });
      },
      5s));
  for (unsigned mac : all) {
    EXPECT_EQ(pump("A", mac).idle_reason, "idle: no live commander") << "pump " << mac;
    EXPECT_EQ(pump("A", mac).commanded_by, "") << "pump " << mac;
  }
  // The control has answered idle polls (its PumpState says so): its own
  // idle action left the pump on.
  {
    const SimStatus s = sim_status(sim, all.size());
    ASSERT_FALSE(s.empty()) << "no status from cdn127-sim";
    EXPECT_TRUE(s.at(kControl).pump_on && s.at(kControl).poll_established)
        << "the control's factory idle action did not hold the pump on";
  }

  // A new commander: pump and N2 ballast on, analog output 5 V.
  constexpr std::uint16_t kHalfScale = 2048;
  for (unsigned mac : all) ASSERT_TRUE(supervisor().command("A", mac, true, true, kHalfScale));
  ASSERT_TRUE(wait_sim(
      sim, all.size(),
      [&](const SimStatus& s) {
        return std::all_of(all.begin(), all.end(), [&](unsigned m) {
          const SimDevice& d = s.at(m);
          return d.pump_on && d.n2_ballast_on && d.aout == kHalfScale;
        });
      },
      10s))
      << "the new commands were not applied";

  // The bridge dies: every device's poll connection times out 4 x EPR after
  // the last poll, and its fault action applies.
  const auto killed = std::chrono::steady_clock::now();
  bridge.signal(SIGKILL);
  const milliseconds fault_bound = 4 * kExpectedPacketRate + patience(kObservation);
  const auto timed_out = time_until(
      sim, all.size(), all, [](const SimDevice& d) { return !d.poll_established; }, killed,
      fault_bound + 5s);
  for (unsigned mac : all) {
    ASSERT_TRUE(timed_out.contains(mac)) << "device " << mac << " still polled after SIGKILL";
    const auto& [after, d] = timed_out.at(mac);
    std::printf(
        "device %u: poll timed out %lld ms after SIGKILL to the bridge (4 x EPR = %lld "
        "ms): pump %s, N2 ballast %s, analog output %u\n",
        mac, static_cast<long long>(after.count()),
        static_cast<long long>((4 * kExpectedPacketRate).count()), d.pump_on ? "on" : "off",
        d.n2_ballast_on ? "on" : "off", d.aout);
    EXPECT_LE(after.count(), fault_bound.count()) << "device " << mac;
    // Not sooner than its watchdog can: an orderly stop would have been.
    EXPECT_GE(after.count(), (2 * kExpectedPacketRate).count()) << "device " << mac;
  }
  for (unsigned mac : configured) {
    const SimDevice& d = timed_out.at(mac).second;
    EXPECT_TRUE(!d.pump_on && !d.n2_ballast_on && d.aout == 0)
        << "device " << mac << " did not apply the configured fault action";
  }
  const SimDevice& control = timed_out.at(kControl).second;
  EXPECT_TRUE(control.pump_on && control.n2_ballast_on && control.aout == kHalfScale)
      << "the control's factory fault action did not hold its outputs";
  const int status = bridge.stop();
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "dnbridge status " << status;
}

// The test as the master, on a raw CAN socket: a request out, the first
// frame with the identifier it waits for, and when it came.
class RawMaster {
 public:
  explicit RawMaster(const std::string& interface) {
    socketcan::SocketOptions o;
    o.timestamps = false;
    auto s = socketcan::CanSocket::open(interface, o);
    if (s) socket_ = std::move(*s);
  }
  bool ok() const { return socket_.is_open(); }

  struct Answer {
    can::CanFrame frame;
    std::chrono::steady_clock::duration after{};
  };
  std::optional<Answer> exchange(std::uint32_t id, std::vector<std::uint8_t> data,
                                 std::uint32_t answer_id, std::chrono::milliseconds timeout) {
    auto frame = can::CanFrame::make(id, Bytes(data.data(), data.size()));
    if (!frame.ok()) return std::nullopt;
    const auto sent = std::chrono::steady_clock::now();
    if (!socket_.write(*frame)) return std::nullopt;
    const auto deadline = sent + timeout;
    for (auto now = sent; now < deadline; now = std::chrono::steady_clock::now()) {
      pollfd p{socket_.fd(), POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now);
      (void)::poll(&p, 1, static_cast<int>(left.count()) + 1);
      for (auto r = socket_.read(); r; r = socket_.read()) {
        if (r->kind == socketcan::Received::Kind::kData && r->frame.id == answer_id) {
          return Answer{r->frame, std::chrono::steady_clock::now() - sent};
        }
      }
    }
    return std::nullopt;
  }

 private:
  socketcan::CanSocket socket_;
};

std::string hex(const can::CanFrame& f) {
  std::string s;
  for (std::size_t i = 0; i < f.len; ++i) s += fmt::format("{}{:02X}", i ? " " : "", f.data[i]);
  return s;
}

// cdn127-sim --reading field on a real CAN stack: the strictest device's
// answers, late by the wall clock as the in-process tests show them late by
// the fake one. The delays are the device's, never scaled: at least 300 ms
// and 3 ms, at most that plus the test's patience.
TEST_F(SystemTest, FieldReadingDeviceAnswersLateOnTheWire) {
  Child& sim = start_sim("vcan0", {5}, {"--reading", "field"});
  RawMaster master("vcan0");
  ASSERT_TRUE(master.ok());
  constexpr std::uint8_t kMaster = 10;
  // MAC 5: 0x42B explicit response, 0x42C request, 0x42D poll, 0x42E
  // Allocate/Release, 0x3C5 poll response.
  const std::vector<std::uint8_t> allocate{kMaster, 0x4B, 0x03, 0x01, 0x03, kMaster};
  std::optional<RawMaster::Answer> a;
  // Unanswered until its duplicate MAC check is over.
  const auto online_by = std::chrono::steady_clock::now() + patience(10s);
  while (!a && std::chrono::steady_clock::now() < online_by) {
    a = master.exchange(0x42E, allocate, 0x42B, 1000ms);
  }
  ASSERT_TRUE(a) << "no answer to Allocate";
  EXPECT_EQ(hex(a->frame), "0A CB 00");
  EXPECT_GE(a->after, 300ms);
  EXPECT_LE(a->after, 300ms + patience(200ms));

  const auto explicit_answer = [&](std::vector<std::uint8_t> request) {
    auto r = master.exchange(0x42C, std::move(request), 0x42B, 300ms + patience(1000ms));
    if (!r) return std::string("no answer");
    EXPECT_GE(r->after, 300ms);
    EXPECT_LE(r->after, 300ms + patience(200ms));
    return hex(r->frame);
  };
  EXPECT_EQ(explicit_answer({kMaster, 0x0E, 0x01, 0x01, 0x06}), "0A 8E 05 00");  // UINT serial
  EXPECT_EQ(explicit_answer({kMaster, 0x0E, 0x01, 0x01, 0x08}), "0A 94 14 FF");  // no State
  EXPECT_EQ(explicit_answer({kMaster, 0x10, 0x40, 0x01, 0x04, 0x01}), "0A 94 0C FF");
  EXPECT_EQ(explicit_answer({kMaster, 0x10, 0x05, 0x02, 0x0E, 0x20, 0x04}), "0A 94 0E FF");
  // A fragmented request: the first fragment acked at once, the last not.
  auto ack = master.exchange(0x42C, {0x8A, 0x00, 0x10, 0x05, 0x02, 0x10, 0x21, 0x04}, 0x42B,
                             patience(1000ms));
  ASSERT_TRUE(ack);
  EXPECT_EQ(hex(ack->frame), "8A C0 00");
  EXPECT_LT(ack->after, 300ms);
  EXPECT_EQ(explicit_answer({0x8A, 0x81, 0x00, 0x25, 0x64, 0x00, 0x30, 0x03}), "0A 94 0E FF");
  // EPR 1050 ms kept as 1100 (steps of 100 ms).
  EXPECT_EQ(explicit_answer({kMaster, 0x10, 0x05, 0x02, 0x09, 0x1A, 0x04}), "0A 90 4C 04");

  auto poll = master.exchange(0x42D, {0x00, 0x00, 0x00, 0x00}, 0x3C5, patience(1000ms));
  ASSERT_TRUE(poll);
  EXPECT_EQ(poll->frame.len, 6u);
  EXPECT_GE(poll->after, 3ms);
  EXPECT_LE(poll->after, 3ms + patience(100ms));
  auto idle = master.exchange(0x42D, {}, 0x3C5, patience(1000ms));
  ASSERT_TRUE(idle);
  EXPECT_EQ(idle->frame.len, 0u);
  EXPECT_GE(idle->after, 3ms);
  EXPECT_TRUE(sim.running()) << "cdn127-sim exited";
}

// The systemd-networkd examples of deploy/networkd, as an operator installs
// them, with Name= set to vcan0 and vcan1 (this kernel has no CAN
// controller, so the [CAN] bit timing is not applied: networkd applies it
// to "can" links only): networkd 252 reads them without a warning and
// brings both links up; a rack then comes online on one of them.
TEST_F(SystemTest, NetworkdExamplesBringTheCanLinksUp) {
  // networkd's own files go to a /run of this kernel's (not the machine's,
  // which is the root filesystem here); with /sys read-only it does not
  // wait for udev, which does not run here.
  ASSERT_EQ(shell("mount -t tmpfs tmpfs /run && mkdir -p /run/systemd/network && "
                  "mount -o remount,ro /sys"),
            0);
  for (const auto& [example, interface] : {std::pair{"80-dnbridge-can0.network", "vcan0"},
                                           std::pair{"80-dnbridge-can1.network", "vcan1"}}) {
    ASSERT_EQ(shell(fmt::format("sed 's/^Name=can[0-9]$/Name={}/' {}/{} > /run/systemd/network/{}",
                                interface, DNBRIDGE_NETWORKD_DIR, example, example)),
              0);
    ASSERT_EQ(shell(fmt::format("grep -qx 'Name={}' /run/systemd/network/{}", interface, example)),
              0)
        << example << " has no Name= line to set";
    ASSERT_EQ(shell(fmt::format("ip link set down {}", interface)), 0);
  }
  const fs::path log = dir_ / "networkd.log";
  children_.push_back(
      std::make_unique<Child>(std::vector<std::string>{"/usr/bin/env", "SYSTEMD_LOG_LEVEL=debug",
                                                       "SYSTEMD_LOG_TARGET=console", NETWORKD_BIN},
                              log));
  Child& networkd = *children_.back();

  const auto deadline = std::chrono::steady_clock::now() + patience(15s);
  const auto up = [] {
    return socketcan::link_state("vcan0") == socketcan::LinkState::kUp &&
           socketcan::link_state("vcan1") == socketcan::LinkState::kUp;
  };
  while (!up() && networkd.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(50ms);  // networkd tells nobody here: look again
  }
  ASSERT_TRUE(up()) << "networkd did not bring vcan0 and vcan1 up:\n" << tail(log);
  EXPECT_EQ(count_lines(log, "Configuring with /run/systemd/network/80-dnbridge-can0.network"), 1u)
      << tail(log);
  EXPECT_EQ(count_lines(log, "Configuring with /run/systemd/network/80-dnbridge-can1.network"), 1u)
      << tail(log);
  // Every line about the files says it matched; none a bad key or value.
  std::ifstream in(log);
  for (std::string l; std::getline(in, l);) {
    if (l.find("/run/systemd/network/80-dnbridge-") == std::string::npos) continue;
    EXPECT_TRUE(l.find("found matching network") != std::string::npos ||
                l.find("Configuring with") != std::string::npos)
        << l;
  }

  start_sim("vcan0", {5, 6});
  start_bridge({{"A", "vcan0", {5, 6}}});
  EXPECT_TRUE(wait_online("A", {5, 6}))
      << "the rack did not come online on the link networkd set up";
}

}  // namespace
}  // namespace dnbridge::system_test
