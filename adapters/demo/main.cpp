// dnbridge-demo: the DeviceNet master scanning a simulated rack of CDN127
// pump interfaces in real time, with a scripted scenario and a live table.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "adapters/demo/rack_table.hpp"
#include "adapters/demo/scenario.hpp"
#include "adapters/sim/bus/pcap_writer.hpp"
#include "adapters/sim/world/sim_rack.hpp"
#include "adapters/version/version.hpp"

namespace {

using namespace dnbridge;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

// Collects life-cycle transitions as lines for the table's event list.
class EventLog final : public devicenet::ScannerObserver {
 public:
  explicit EventLog(TimePoint start) : start_(start) {}
  void add(TimePoint at, const std::string& text) {
    lines_.push_back(
        fmt::format("{:7.2f} s  {}", std::chrono::duration<double>(at - start_).count(), text));
    while (lines_.size() > 12) lines_.pop_front();
  }
  void on_port_state(devicenet::PortState s, const std::string& reason, TimePoint at) override {
    add(at, fmt::format("port {}: {}", devicenet::to_string(s), reason));
  }
  void on_node_state(devicenet::MacId mac, devicenet::NodeState, devicenet::NodeState to,
                     const std::string& reason, TimePoint at) override {
    add(at, fmt::format("node {} {}: {}", mac.value(), devicenet::to_string(to), reason));
  }
  const std::deque<std::string>& lines() const { return lines_; }

 private:
  TimePoint start_;
  std::deque<std::string> lines_;
};

TimePoint mono_now() {
  return TimePoint(
      std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now().time_since_epoch()));
}

// The simulated rack: pumps at MACs 1..nodes, polled every 50 ms; the last
// one of several uses the CDN118 layout (no analog inputs).
sim::SimRackConfig rack_config(unsigned nodes, unsigned bitrate_k) {
  sim::SimRackConfig config;
  config.bus.bitrate = bitrate_k * 1000;
  config.port.master_mac = devicenet::MacId::from(0).value();
  config.port.vendor_id = 59;
  config.port.serial_number = 0xDB000001;
  for (unsigned m = 1; m <= nodes; ++m) {
    rack::PumpConfig p;
    p.node.mac = devicenet::MacId::from(m).value();
    p.node.name = fmt::format("pump-{}", m);
    p.node.poll_period = milliseconds(50);
    p.node.expected_packet_rate = milliseconds(250);
    p.io = profiles::cdn127::preset(m == nodes && nodes > 1
                                        ? profiles::cdn127::ConfigurationPreset::kCdn118
                                        : profiles::cdn127::ConfigurationPreset::kCdn127);
    config.pumps.push_back(std::move(p));
  }
  return config;
}

// The table, appended (plain) or redrawn over the screen.
void draw(const std::string& table, bool plain) {
  if (plain) {
    std::fputs(table.c_str(), stdout);
    std::fputs("\n", stdout);
  } else {
    std::fputs("\x1b[H\x1b[2J", stdout);
    std::fputs(table.c_str(), stdout);
  }
  std::fflush(stdout);
}

// Closes the capture and says what it holds; false when frames were lost.
bool close_capture(sim::BusCapture& capture, const std::string& path) {
  const std::uint64_t frames = capture.frames();
  if (capture.close()) {
    std::fprintf(stderr, "dnbridge-demo: %llu frames captured to %s\n",
                 static_cast<unsigned long long>(frames), path.c_str());
    return true;
  }
  std::fprintf(stderr, "dnbridge-demo: capture to %s incomplete: %llu write errors (%s)\n",
               path.c_str(), static_cast<unsigned long long>(capture.writer().write_errors()),
               capture.writer().error().message().c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dnbridge-demo: the DeviceNet master of dnbridge scanning a simulated rack of CDN127 pump\n"
      "interfaces on an in-process CAN bus, in real time, with a scripted scenario."};
  unsigned nodes = 8;
  double duration_s = 45;
  unsigned bitrate_k = 500;
  double loss_percent = 0;
  bool plain = !isatty(STDOUT_FILENO);
  std::string pcap_path;
  app.add_option("-n,--nodes", nodes, "Number of simulated pumps (MACs 1..N)")
      ->check(CLI::Range(1, 63));
  app.add_option("-d,--duration", duration_s, "Seconds to run; 0 runs until Ctrl-C")
      ->check(CLI::NonNegativeNumber);
  app.add_option("-b,--bitrate", bitrate_k, "Bus bit rate in kbit/s")
      ->check(CLI::IsMember({125, 250, 500}));
  app.add_option("--loss", loss_percent, "Percentage of frames the bus loses")
      ->check(CLI::Range(0.0, 50.0));
  app.add_flag("--plain", plain, "Print snapshots instead of redrawing the screen");
  app.add_option("--pcap", pcap_path,
                 "Record every frame on the bus to FILE (pcap, SocketCAN link type); read it with\n"
                 "  tshark -r FILE -d 'can.subdissector,devicenet'");
  app.set_version_flag("--version",
                       dnbridge::version::text("dnbridge-demo", dnbridge::version::Dds::kNotUsed),
                       "Print the version and source revision, and exit");
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  const sim::SimRackConfig config = rack_config(nodes, bitrate_k);
  std::vector<unsigned> macs;
  for (const auto& p : config.pumps) macs.push_back(p.node.mac.value());

  sim::SimRack rack(config);
  EventLog events(rack.now());
  rack.observe(events);
  if (loss_percent > 0) {
    sim::FaultRule loss;
    loss.action = sim::FaultAction::kDrop;
    loss.rate = loss_percent / 100.0;
    rack.world().bus().faults().add(loss);
  }

  const auto steps = demo::make_scenario(macs);
  const TimePoint virtual_start = rack.now();
  const TimePoint real_start = mono_now();
  const Duration offset = virtual_start - real_start;  // virtual = real + offset

  // The run is in real time, so the capture carries the wall-clock time.
  std::unique_ptr<sim::BusCapture> capture;
  if (!pcap_path.empty()) {
    try {
      capture = std::make_unique<sim::BusCapture>(
          rack.world().bus(), sim::PcapWriter(pcap_path, virtual_start,
                                              std::chrono::system_clock::now().time_since_epoch()));
    } catch (const std::system_error& e) {
      std::fprintf(stderr, "dnbridge-demo: %s\n", e.what());
      return 2;
    }
  }
  rack.start();

  const Duration render_every = plain ? seconds(5) : milliseconds(250);
  TimePoint next_render = virtual_start;
  std::size_t next_step = 0;
  unsigned cycle = 0;
  const TimePoint end = duration_s > 0
                            ? virtual_start + std::chrono::duration_cast<Duration>(
                                                  std::chrono::duration<double>(duration_s))
                            : kNever;
  bool stopping = false;
  TimePoint stop_deadline = kNever;

  auto render = [&] { draw(demo::render_rack(rack, virtual_start, events.lines()), plain); };

  for (;;) {
    const TimePoint target = mono_now() + offset;
    // Scenario steps at their exact virtual time.
    while (!stopping && !steps.empty()) {
      const auto& step = steps[next_step];
      const TimePoint at = virtual_start + demo::scenario_period() * cycle + step.at;
      if (at > target) break;
      rack.world().run_until(at);
      events.add(at, step.what);
      step.apply(rack, at);
      if (++next_step == steps.size()) {
        next_step = 0;
        ++cycle;
      }
    }
    rack.world().run_until(target);

    if (!stopping && (g_stop || target >= end)) {
      stopping = true;
      stop_deadline = target + seconds(3);
      events.add(target, "shutting down: every pump idle, then released");
      rack.scanner().stop(target);
    }
    if (stopping && (rack.scanner().stopped() || target >= stop_deadline)) break;
    if (target >= next_render) {
      render();
      next_render = target + render_every;
    }
    const TimePoint wake =
        std::min({rack.world().next_event(), next_render, target + milliseconds(50)});
    std::this_thread::sleep_until(std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            (wake - offset).time_since_epoch())));
  }
  render();
  if (capture && !close_capture(*capture, pcap_path)) return 2;
  return rack.scanner().state() == devicenet::PortState::kStopped ? 0 : 1;
}
