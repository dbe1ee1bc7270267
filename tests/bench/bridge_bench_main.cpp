// dnbridge-bench: what the bridge costs in latency and CPU, beside what Cyclone
// DDS itself costs on the same machine in the same run.
//
//   (0) Cyclone's own one-way latency: ddsperf ping and pong (two processes,
//       waitset mode, on loopback), one-way = round trip / 2 (ddsperf prints
//       its round trips halved already), run beside each latency
//       measurement below, over the same seconds.
//   (0b) Cyclone alone on the path of a command: PumpCommands written by the
//       commander process, taken here, nothing behind it, twice: on a
//       waitset thread, and by a listener on Cyclone's thread (as the bridge
//       takes them); one way, measured on CLOCK_MONOTONIC at both ends. The
//       bridge's own addition to (2) is measured against the listener's.
//   (0c) Cyclone alone on the state path: PumpStates written in this process
//       with the bridge's QoS, in the pattern of (1)'s poll responses, taken
//       by the subscriber process as in (1); the bridge's own addition to (1)
//       is measured against it.
//   (0d) one thread of this process waking another on the same CPU, nothing
//       else running: the one hand-over each of (1) and (2) makes.
//   (1) poll response received by the master -> PumpState taken by a
//       subscriber in another process: wall clock at take - source timestamp
//       (the bridge stamps each sample with the CAN receive time of the poll
//       response it comes from). Split sample by sample (matched by node and
//       analog value): the response's way to the port's thread (the CAN
//       controller waking it), and from there to the take.
//   (2) PumpCommand written in another process -> the poll frame carrying the
//       new outputs, written by the master to its CAN interface, and its start
//       of frame on the simulated bus (after any frame already on the wire
//       and arbitration): both ends on CLOCK_MONOTONIC, which the two
//       processes share. Commands come at random gaps, so that they meet the
//       poll schedule at every phase. (1) and (2) are measured with polls
//       every 10 ms and every 100 ms (the shipped default). Commands that
//       meet a poll in flight: from its response to the new poll written.
//       The others split: until the port's thread woke for the command, and
//       from there to the frame written; the first again at the wake-up the
//       bridge's listener asks for (the end of its work on Cyclone's
//       thread), which leaves the hand-over to the port's thread alone.
//   (3) CPU time of the bridge per second of wall time, 4 ports x 63 nodes
//       polled every 10 ms, the simulated devices' threads left out; (3b)
//       the same with a PumpState per poll; (3c) Cyclone alone writing (3b)'s
//       samples, CPU per sample, which splits (3b)'s cost per sample into
//       Cyclone's write and the bridge's own work; (3d) (3c) with Cyclone's
//       write batching.
//
// Each measurement has a file of its own: bridge_bench_reference.cpp (0),
// bridge_bench_command_alone.cpp (0b), bridge_bench_state_alone.cpp (0c),
// bridge_bench_handover.cpp (0d), bridge_bench_latency.cpp (1) and (2),
// bridge_bench_cpu.cpp (3) to (3d); this one has the options and the run.
//
// The bridge runs in this process (daemon::Daemon, configuration built here,
// each port on a ThreadedSimBackend: the simulated bus and devices on a
// thread of their own; bridge_bench_bridge.cpp). The subscriber and
// commander is this same program re-executed with --client
// (bridge_bench_client.cpp): another process, another DDS participant. Every
// DDS participant of the run, ddsperf's included, is pinned to the loopback
// interface with a discovery tag of this run's own. The measured process
// (this one; ddsperf pong) and its peer (the client; ddsperf ping) each run
// on a CPU of their own, and CPUs are held out of idle halts for the run
// (see --help to change either).
//
// It reports figures; it exits non-zero only when the run itself fails.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "adapters/daemon/log_sink.hpp"
#include "adapters/dds/loopback.hpp"
#include "bridge_bench.hpp"

namespace dnbridge::bench {
namespace {

// The bridge's receive and frame times are std::chrono::steady_clock (the
// simulated bus runs on it); the commander stamps its writes with
// clock_gettime(CLOCK_MONOTONIC). They are one clock if every steady_clock
// reading falls between two CLOCK_MONOTONIC readings taken around it.
bool steady_clock_is_monotonic() {
  for (int i = 0; i < 1000; ++i) {
    const auto a = monotonic_ns();
    const auto s = steady_ns();
    const auto b = monotonic_ns();
    if (s < a || s > b) return false;
  }
  return true;
}

// Holds CPUs out of idle halts for the rest of the process's life, unless
// told not to, and says which.
void hold_cpus_awake_for_the_run(bool hold_awake) {
  const int awake = hold_awake ? hold_cpus_awake() : -1;
  if (awake >= 0) {
    fmt::print("CPU idle: /dev/cpu_dma_latency held at 0 us for the whole run (no CPU halts)\n");
  } else {
    fmt::print("CPU idle: {}\n", hold_awake ? "/dev/cpu_dma_latency could not be held (not root?): "
                                              "CPUs halt when idle"
                                            : "CPUs halt when idle (--allow-idle)");
  }
}

// (0b), (0c), (0d), (1) and (2). Each latency measurement has ddsperf
// running beside it: Cyclone's own latency and the bridge's are taken over
// the same seconds, on the same CPUs.
void measure_latencies(const Run& run) {
  const Options& o = run.options;
  if (o.latency_seconds > 0 && o.direct_seconds > 0) measure_thread_handover(run);
  // (0b), the listener's: what the bridge's command path adds is measured
  // against it.
  std::optional<Summary> listener_alone;
  if (o.latency_seconds > 0 && o.direct_seconds > 0) {
    listener_alone = measure_command_path_alone(run);
  }
  for (const int poll_ms : o.latency_poll_ms) {
    if (o.latency_seconds <= 0) break;
    std::optional<Summary> state_alone;
    if (o.direct_seconds > 0) state_alone = measure_state_path_alone(run, poll_ms);
    measure_bridge_latency(run, poll_ms, state_alone, listener_alone);
  }
}

int run_bench(const Options& o) {
  const int domain = o.domain >= 0 ? o.domain : 200 + static_cast<int>(getpid() % 30);
  const std::string tag = fmt::format("dnbridge-bench-{}", getpid());
  setenv("CYCLONEDDS_URI", dds::loopback_config(tag).c_str(), 1);
  daemon::StderrLogSink log(LogLevel::kWarn);

  print_run_header("dnbridge benchmark", domain, tag);
  hold_cpus_awake_for_the_run(o.hold_awake);

  // The measured process on one CPU, its peer on another, for the bridge as
  // for ddsperf: a hand-over between threads of one process then stays on
  // its CPU (on a virtual machine waking another, idle, CPU can cost tens of
  // microseconds), and each pair is measured in the same layout.
  const Placement cpus =
      place_processes(o.pin, o.bridge_cpu, o.peer_cpu, "the bridge (this process, every thread)",
                      "the subscriber/commander process");

  if (!steady_clock_is_monotonic()) {
    fmt::print(stderr,
               "std::chrono::steady_clock is not CLOCK_MONOTONIC here: (2) cannot be measured\n");
    return 1;
  }
  fmt::print(
      "clock check: std::chrono::steady_clock reads CLOCK_MONOTONIC (1000 readings bracketed)\n\n");

  const Run run{o, domain, cpus, log};
  measure_latencies(run);
  measure_cpu(run);
  fmt::print("load average at end: {}\n", load_average());
  return 0;
}

void add_bench_options(CLI::App& app, Options& o) {
  app.add_option("--ddsperf-rate", o.ddsperf_rate, "ddsperf pings per second")
      ->capture_default_str();
  app.add_option("--latency-seconds", o.latency_seconds, "(1) and (2), each run; 0 to skip")
      ->capture_default_str();
  app.add_option("--direct-seconds", o.direct_seconds, "(0b) and (0c), each run; 0 to skip")
      ->capture_default_str();
  app.add_option("--latency-poll-ms", o.latency_poll_ms, "a run of (1) and (2) per poll period")
      ->capture_default_str();
  app.add_option("--latency-nodes", o.latency_nodes, "nodes for (1) and (2)")
      ->capture_default_str();
  app.add_option("--command-interval-ms", o.command_interval_ms, "(2)")->capture_default_str();
  app.add_option("--cpu-seconds", o.cpu_seconds, "(3) measurement window")->capture_default_str();
  app.add_option("--busy-seconds", o.busy_seconds, "(3b), (3c) and (3d) windows, 0 to skip")
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain (default: from the process id)");
  app.add_option("--bridge-cpu", o.bridge_cpu, "CPU of the bridge and of ddsperf pong")
      ->capture_default_str();
  app.add_option("--peer-cpu", o.peer_cpu, "CPU of the subscriber/commander and of ddsperf ping")
      ->capture_default_str();
  app.add_flag("!--no-pin", o.pin, "let the kernel place every process and thread");
  app.add_flag("!--allow-idle", o.hold_awake, "do not hold /dev/cpu_dma_latency at 0");
}

// The client role (re-executed by the benchmark itself), hidden from --help.
void add_client_options(CLI::App& app, ClientOptions& client, std::string& ports) {
  app.add_option("--client", client.mode)->group("");
  app.add_option("--ports", ports)->group("");
  app.add_option("--nodes", client.nodes)->group("");
  app.add_option("--seconds", client.seconds)->group("");
  app.add_option("--command-interval-us", client.command_interval_us)->group("");
  app.add_flag("--command-once", client.command_once)->group("");
}

// "A,B,C" as {"A", "B", "C"}.
std::vector<std::string> split_ports(const std::string& ports) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at <= ports.size();) {
    const auto comma = std::min(ports.find(',', at), ports.size());
    out.push_back(ports.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

}  // namespace
}  // namespace dnbridge::bench

int main(int argc, char** argv) {
  using namespace dnbridge::bench;
  CLI::App app{"dnbridge-bench: the bridge's latency and CPU time beside Cyclone DDS's own"};
  Options o;
  ClientOptions client;
  std::string ports;
  add_bench_options(app, o);
  add_client_options(app, client, ports);
  CLI11_PARSE(app, argc, argv);

  try {
    if (!client.mode.empty()) {
      client.domain = o.domain;
      client.ports = split_ports(ports);
      return run_client(client);
    }
    return run_bench(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge-bench: %s\n", e.what());
    return 1;
  }
}
