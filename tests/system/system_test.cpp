// dnbridge on a real Linux CAN stack: the bridge, cdn127-sim and a DDS
// supervisor as separate processes on vcan interfaces of a kernel of their
// own. run_in_vm.sh runs each test in User-Mode Linux or QEMU.
#include <fmt/format.h>
#include <signal.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>
#include <utility>

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

  Child& start_sim(const std::string& interface, const std::vector<unsigned>& macs) {
    std::vector<std::string> argv{CDN127_SIM_BIN, "--iface", interface};
    for (auto m : macs) {
      argv.push_back("--mac");
      argv.push_back(std::to_string(m));
    }
    children_.push_back(
        std::make_unique<Child>(argv, dir_ / fmt::format("cdn127-sim-{}.log", interface)));
    return *children_.back();
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

  // Wireshark's DeviceNet dissector on the whole capture (devicenet-facts §9).
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

  sim.send("power-cycle 6");
  ASSERT_TRUE(wait_offline("A", 6)) << "the master did not notice the power cycle";
  ASSERT_TRUE(wait_online("A", {5, 6})) << "node 6 did not come back after its power cycle";

  sim.send("power-off 5");
  ASSERT_TRUE(wait_offline("A", 5));
  EXPECT_TRUE(supervisor().online("A", 6));
  sim.send("power-on 5");
  ASSERT_TRUE(wait_online("A", {5, 6})) << "node 5 did not come back after power-on";
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
