#pragma once
// What the system tests share. They run inside a kernel of their own with
// the CAN modules, User-Mode Linux or QEMU (run_in_vm.sh boots it,
// guest_init.sh sets it up): vcan0 and vcan1 exist, DDS is pinned to lo. Each test starts the real
// programs (dnbridge, cdn127-sim) as child processes and watches the bridge
// through DDS, as a supervisor would.
#include <gtest/gtest.h>
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/sim/bus/pcap_writer.hpp"
#include "adapters/socketcan/can_socket.hpp"

namespace dnbridge::system_test {

namespace fs = std::filesystem;

// A child process: stdout and stderr to `log`, stdin from a pipe of ours.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const fs::path& log);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // A line to the child's standard input.
  void send(const std::string& line);
  // SIGTERM, then SIGKILL after `grace`; the exit status (waitpid's).
  int stop(std::chrono::milliseconds grace = std::chrono::milliseconds(5000));
  bool running();
  void signal(int number);
  const fs::path& log() const { return log_; }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1;
  fs::path log_;
  int status_ = 0;
};

// Every frame on an interface, into a pcap file, from a thread of its own.
class Capture {
 public:
  Capture(const std::string& interface, const fs::path& file);
  ~Capture();
  // Stops and closes; the number of frames written.
  std::uint64_t stop();
  // Every frame captured, in order; after stop().
  const std::vector<can::CanFrame>& frames() const { return frames_; }

 private:
  void run();
  std::chrono::nanoseconds epoch_;  // wall time of the capture's start
  socketcan::CanSocket socket_;
  sim::PcapWriter writer_;
  std::atomic<bool> stop_{false};
  std::vector<can::CanFrame> frames_;
  std::thread thread_;
};

// The latest samples of the bridge's state topics, by key.
struct PumpKey {
  std::string port;
  unsigned mac;
  friend auto operator<=>(const PumpKey&, const PumpKey&) = default;
};

struct PumpSeen {
  bool online = false;
  bool pump_running = false;
  bool alarm_active = false;
  bool outputs_idle = false;
  std::string idle_reason;
  bool pump_on = false;  // outputs
  bool n2_ballast_on = false;
  std::uint16_t analog_output_raw = 0;
  float analog_in1 = 0;
  std::string commanded_by;
  dds::Timestamp source_time{};
  dds::Timestamp received{};
};

struct PortSeen {
  dnbridge_BusState bus_state = dnbridge_BUS_STATE_UNKNOWN;
  dnbridge_PortLifecycle state = dnbridge_PORT_STOPPED;
  std::string reason;
  unsigned nodes_online = 0;
  unsigned nodes_configured = 0;
  std::string can_interface;
};

class Supervisor {
 public:
  explicit Supervisor(const std::string& rack);

  // Takes what arrived and folds it into the maps.
  void update();
  // Until `done` holds (checked on every arrival and every 200 ms), or
  // `timeout` scaled by patience(): how long the test waits, not a bound
  // the product must meet.
  bool wait_until(const std::function<bool()>& done, std::chrono::seconds timeout);

  bool command(const std::string& port, unsigned mac, bool pump_on, bool n2_ballast_on = false,
               std::uint16_t analog_output_raw = 0);

  const std::map<PumpKey, PumpSeen>& pumps() const { return pumps_; }
  const std::map<std::string, PortSeen>& ports() const { return ports_; }
  bool online(const std::string& port, unsigned mac) const;
  bool all_online(const std::string& port, const std::vector<unsigned>& macs) const;
  std::string describe() const;

 private:
  std::string rack_;
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpState> pump_topic_;
  dds::Topic<dnbridge_PortStatus> port_topic_;
  dds::Topic<dnbridge_PumpCommand> command_topic_;
  dds::Reader<dnbridge_PumpState> pump_reader_;
  dds::Reader<dnbridge_PortStatus> port_reader_;
  dds::Writer<dnbridge_PumpCommand> command_writer_;
  dds::ReadCondition pump_data_;
  dds::ReadCondition port_data_;
  dds::WaitSet waitset_;
  std::map<PumpKey, PumpSeen> pumps_;
  std::map<std::string, PortSeen> ports_;
};

// The guest's speed factor against the machine that runs the tests
// (DNBRIDGE_SYSTEM_SLOWDOWN, measured by guest_init.sh; 1 when unset), and a
// wait of the test's own scaled by it. Bounds the product must meet (fault
// detection within 4 x EPR, say) are never scaled.
double guest_slowdown();
std::chrono::milliseconds patience(std::chrono::milliseconds base);

// The work directory of this run (DNBRIDGE_SYSTEM_WORK, set by the guest's
// init script), one subdirectory per test.
fs::path work_dir();

// Runs a shell command; its exit status.
int shell(const std::string& command);

// The poll period and expected packet rate of every node of rack_config():
// short, so that lost nodes are noticed and found again within seconds. A
// device whose poll stops applies its fault actions 4 x EPR after the last.
inline constexpr std::chrono::milliseconds kPollPeriod{50};
inline constexpr std::chrono::milliseconds kExpectedPacketRate{250};

// A rack configuration: `ports` is {port name, interface, node MACs}, and
// TOML lines of a node's own by MAC (`safe_state = "device"`, say).
struct PortSpec {
  std::string name;
  std::string interface;
  std::vector<unsigned> macs;
  std::map<unsigned, std::string> node_settings = {};
};
std::string rack_config(const std::string& rack, const std::vector<PortSpec>& ports);

}  // namespace dnbridge::system_test
