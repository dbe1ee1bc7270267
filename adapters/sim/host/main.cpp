// cdn127-sim: simulated CDN127 DeviceNet pump interfaces on a SocketCAN
// interface, for trying a dnbridge configuration before the rack exists.
#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "adapters/sim/host/control.hpp"
#include "adapters/sim/host/device_config.hpp"
#include "adapters/sim/host/sim_host.hpp"
#include "adapters/version/version.hpp"

namespace {

using namespace dnbridge;

// A device configuration that cannot be used: every problem printed,
// FILE:LINE:COLUMN each (as dnbridge does for its own).
constexpr int kBadConfiguration = 2;

class StderrSink final : public LogSink {
 public:
  explicit StderrSink(LogLevel level) : level_(level) {}
  bool enabled(LogLevel level) const noexcept override { return level >= level_; }
  void write(LogLevel level, std::string_view component, std::string_view message) override {
    std::lock_guard lock(mutex_);
    fmt::print(stderr, "{:<5} {}: {}\n", to_string(level), component, message);
    std::fflush(stderr);
  }

 private:
  LogLevel level_;
  std::mutex mutex_;
};

// The devices --mac, --device-config and --reading describe; nullopt, with
// every problem printed, when they cannot be used.
std::optional<std::vector<sim::host::DeviceSpec>> devices_of(const std::vector<unsigned>& macs,
                                                             const std::string& config_file,
                                                             const std::string& reading_name) {
  try {
    sim::host::DeviceConfig config;
    if (!config_file.empty()) config = sim::host::load_device_config(config_file);
    std::vector<devicenet::MacId> ids;
    ids.reserve(macs.size());
    for (auto m : macs) ids.push_back(devicenet::MacId::from_bits(m));
    const auto reading =
        reading_name == "field" ? sim::host::Reading::kField : sim::host::Reading::kLenient;
    return sim::host::device_options(ids, config, reading);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return std::nullopt;
  }
}

// Where commands come from (--control): standard input for "-", -1 for
// "none", else a FIFO, created if missing; nullopt when it cannot be opened.
std::optional<int> open_control(const std::string& control) {
  if (control == "none") return -1;
  if (control == "-") {
    (void)::fcntl(STDIN_FILENO, F_SETFL, ::fcntl(STDIN_FILENO, F_GETFL) | O_NONBLOCK);
    return STDIN_FILENO;
  }
  if (::mkfifo(control.c_str(), 0600) < 0 && errno != EEXIST) {
    std::fprintf(stderr, "cannot create the control FIFO %s: %s\n", control.c_str(),
                 std::strerror(errno));
    return std::nullopt;
  }
  // Read and write: the FIFO never reports end of file when writers come and go.
  const int fd = ::open(control.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    std::fprintf(stderr, "cannot open the control FIFO %s: %s\n", control.c_str(),
                 std::strerror(errno));
    return std::nullopt;
  }
  return fd;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "cdn127-sim: simulated CDN127 DeviceNet pump interfaces (Group 2 only slaves) on a "
      "SocketCAN\n"
      "interface, one CAN_RAW socket each, as if each were a device on the bus.\n\n"
      "  cdn127-sim --iface vcan0 --mac 5 --mac 6\n\n"
      "Every device powers up at start (duplicate MAC check, then waits for a master), with\n"
      "the CDN127's identity (vendor 59, product type 27, product code 1888), serial number\n"
      "0x10000 + MAC and the CDN127 preset configuration.\n\n"
      "Where the CDN127 manual can be read more than one way, devices in the field differ;\n"
      "by default every device takes the simulator's lenient reading. --reading field gives\n"
      "every device the strictest one, --device-config FILE chooses per device (TOML; keys\n"
      "below, the file's [defaults] apply to every device, those given only with --mac too):\n"
      "  [[device]]\n"
      "  mac = 5                                          # also simulates MAC 5\n"
      "  configuration_locked_while_poll_allocated = true # Configuration Set/Reset: 0x0C\n"
      "                                                   # while the poll connection exists\n"
      "  poll_paths_fixed = true          # Connection 2 attributes 14/16 Get only (0x0E)\n"
      "  idle_poll_answered_empty = true  # idle poll answered with 0 bytes\n"
      "  no_ack_of_last_request_fragment = true  # the response answers the last fragment\n"
      "  release_keeps_outputs = true     # a Release of the poll connection keeps outputs\n"
      "  explicit_response_delay_ms = 300 # explicit and Allocate/Release answers this late\n"
      "  poll_response_delay_ms = 3       # poll responses this late\n"
      "  serial_number_bytes = 2          # Identity serial: 2 (UINT) or 4 (UDINT)\n"
      "  identity_state_supported = false # Identity attribute 8 answers 0x14\n"
      "  epr_resolution_ms = 100          # expected packet rates rounded up to this\n"
      "--reading field is all of these as shown. A device's options: --reading, then\n"
      "[defaults], then its [[device]] (deploy/config/cdn127-sim-example.toml).\n"
      "Not a reading, so not in --reading field, a key of the same tables:\n"
      "  unsafe_factory_output_actions = true  # E2 as it leaves the factory (and after\n"
      "      # Identity Reset type 1): DOP fault/idle actions 1 (no change), AOP fault/idle\n"
      "      # states 0 (hold): the pump stays on when the master goes idle or away. false\n"
      "      # (default): each DOP goes Off (action 0, value 0), the AOP holds (state 0).\n\n" +
      std::string(sim::host::control_help())};
  std::string interface;
  std::vector<unsigned> macs;
  std::string control = "-";
  std::string level_name = "info";
  std::string device_config_file;
  std::string reading_name = "lenient";
  app.add_option("-i,--iface", interface, "SocketCAN interface (vcan0, can0)")->required();
  app.add_option("-m,--mac", macs,
                 "MAC ID of a simulated device, 0..63 (repeat for more; required unless "
                 "--device-config has [[device]] tables)")
      ->check(CLI::Range(0, 63));
  app.add_option("--device-config", device_config_file,
                 "TOML file of per-device readings of the manual ([defaults], [[device]])");
  app.add_option("--reading", reading_name,
                 "lenient: the simulator's own reading; field: the strictest device (every "
                 "reading above, explicit responses 300 ms and polls 3 ms late, 2-byte serial, "
                 "no Identity State, EPR in steps of 100 ms)")
      ->check(CLI::IsMember({"lenient", "field"}))
      ->capture_default_str();
  app.add_option("--control", control,
                 "Where commands come from: \"-\" standard input (end of input quits), a FIFO "
                 "path (created if missing; runs until SIGINT/SIGTERM), or \"none\"")
      ->capture_default_str();
  app.add_option("--log-level", level_name, "trace, debug, info, warn or error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->capture_default_str();
  app.set_version_flag("--version",
                       dnbridge::version::text("cdn127-sim", dnbridge::version::Dds::kNotUsed),
                       "Print the version and source revision, and exit");
  CLI11_PARSE(app, argc, argv);

  std::optional<std::vector<sim::host::DeviceSpec>> devices =
      devices_of(macs, device_config_file, reading_name);
  if (!devices) return kBadConfiguration;
  if (devices->empty()) {
    std::fprintf(stderr, "no device: give --mac, or [[device]] in --device-config (--help)\n");
    return kBadConfiguration;
  }

  LogLevel level = LogLevel::kInfo;
  for (auto l :
       {LogLevel::kTrace, LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarn, LogLevel::kError}) {
    if (level_name == to_string(l)) level = l;
  }
  StderrSink log(level);

  // SIGINT and SIGTERM are read from a signalfd in the loop.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigprocmask(SIG_BLOCK, &signals, nullptr);

  const bool quit_at_end = control == "-";
  const std::optional<int> control_fd = open_control(control);
  if (!control_fd) return kBadConfiguration;

  try {
    sim::host::SimHost host(interface, std::move(*devices), log);
    std::printf("ready\n");
    std::fflush(stdout);
    host.run(*control_fd, quit_at_end, stdout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cdn127-sim: %s\n", e.what());
    return 1;
  }
  return 0;
}
