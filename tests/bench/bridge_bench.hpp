#pragma once
// dnbridge-bench's parts (bridge_bench_main.cpp describes the program): its
// options, what every measurement of a run shares, the client process as the
// benchmark sees it, and each measurement's entry point.
#include <fmt/format.h>
#include <time.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bench_process.hpp"
#include "bridge/common/log.hpp"
#include "bridge/common/time.hpp"
#include "ddsperf.hpp"
#include "figures.hpp"

namespace dnbridge::bench {

// The bridge's rack, and the partition of every command of the run.
constexpr const char* kRack = "bench";

struct Options {
  int ddsperf_rate = 500;
  int ddsperf_size = 128;
  double latency_seconds = 25;
  double direct_seconds = 15;
  std::vector<int> latency_poll_ms{10, 100};
  unsigned latency_nodes = 8;
  int command_interval_ms = 10;
  double cpu_seconds = 20;
  double busy_seconds = 10;
  int domain = -1;
  bool pin = true;
  bool hold_awake = true;
  int bridge_cpu = 1;
  int peer_cpu = 0;
};

// ---------------------------------------------------------------------------
// Clocks and figures

inline std::int64_t process_cpu_ns() { return clock_ns(CLOCK_PROCESS_CPUTIME_ID); }
inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline std::string us(double v) { return fmt::format("{:.1f} us", v); }

// What every measurement of a run shares.
struct Run {
  const Options& options;
  int domain;
  Placement cpus;
  LogSink& log;
};

// ---------------------------------------------------------------------------
// The client process: subscriber and commander (bridge_bench_client.cpp)

struct ClientOptions {
  std::string mode;  // "latency", "count", "oneway" or "state"
  int domain = 0;
  std::vector<std::string> ports;
  unsigned nodes = 0;           // MACs 1..nodes on each port
  double seconds = 0;           // measurement window after every node is online
  int command_interval_us = 0;  // latency: one command every so often
  bool command_once = false;    // count: one command per node at the start
};

// The client's role, run in the re-executed process.
int run_client(const ClientOptions& o);

// The command line that re-executes this program as a client.
std::vector<std::string> client_args(const std::string& mode, int domain,
                                     const std::vector<std::string>& ports, unsigned nodes,
                                     double seconds);

// What a client printed.
struct ClientOutput {
  std::vector<double> state_us;
  // The same, with the sample's key and analog input.
  struct State {
    double us;
    std::size_t key;
    unsigned value;
  };
  std::vector<State> states;
  struct Cmd {
    unsigned mac, value;
    std::int64_t at;
  };
  std::vector<Cmd> commands;
  std::uint64_t taken = 0;
  double window_s = 0;
};

// Reads a client's output to its end; its "ready" line (every node online)
// calls `on_ready`, its "taken" line (end of its window) `on_end`. Throws
// when the client failed.
ClientOutput read_client(Child child, double seconds, const std::function<void()>& on_ready,
                         const std::function<void()>& on_end);

// ---------------------------------------------------------------------------
// (0) Cyclone DDS's own latency, beside each latency measurement
// (bridge_bench_reference.cpp)

// ddsperf's one-way latency (us).
struct Reference {
  double p50 = 0, p99 = 0;
};

// ddsperf run beside a measurement, over the same seconds, on the same CPUs.
class DdsperfBeside {
 public:
  explicit DdsperfBeside(const Run& run) : run_(run) {}

  // At the measurement's start, for as long as it lasts.
  void start(double seconds);
  // Once the measurement has ended: ddsperf's figures, printed as (0).
  Reference report();

 private:
  const Run& run_;
  std::optional<Ddsperf> ddsperf_;
};

// ---------------------------------------------------------------------------
// The measurements, in the order a run makes them

// (0d), bridge_bench_handover.cpp.
void measure_thread_handover(const Run& run);

// (0b), bridge_bench_command_alone.cpp: the listener's figures, which (2)
// is measured against.
std::optional<Summary> measure_command_path_alone(const Run& run);

// (0c), bridge_bench_state_alone.cpp, in the pattern of (1) with polls every
// `poll_ms`: its figures, which (1) is measured against; none without samples.
std::optional<Summary> measure_state_path_alone(const Run& run, int poll_ms);

// (1) and (2), bridge_bench_latency.cpp, with polls every `poll_ms`.
void measure_bridge_latency(const Run& run, int poll_ms, const std::optional<Summary>& state_alone,
                            const std::optional<Summary>& listener_alone);

// (3) to (3d), bridge_bench_cpu.cpp.
void measure_cpu(const Run& run);

// ---------------------------------------------------------------------------
// Cyclone DDS alone on the state path, for (0c), (3c) and (3d)
// (bridge_bench_state_alone.cpp)

// PumpStates written by this process with the bridge's participant and QoS
// (the bridge's default partition, state_writer_qos), each with a new analog
// input value, and taken by the subscriber process as in (1). Every
// `period`, every instance (ports x nodes) once, in `batches` batches
// `spacing` apart, from a thread of its own, from the client's "ready" until
// its window ends.
struct StatePattern {
  std::vector<std::string> ports;
  unsigned nodes = 0;
  Duration period{};
  unsigned batches = 1;
  Duration spacing{};
  // Cyclone's write batching (dds_write_set_batch, process-wide): a batch's
  // samples go out together at its end (dds_write_flush), not one datagram
  // per write.
  bool batched = false;
};

struct DirectStateResult {
  std::vector<double> latency_us;  // wall clock at take - source timestamp, as (1)
  std::uint64_t written = 0;       // within the window
  std::uint64_t taken = 0;
  double window_s = 0;
  double process_cpu_s = 0;  // this process over the window (Cyclone's threads included)
  double write_cpu_s = 0;    // the writing thread, inside its batches of writes
};

// `pattern` written for `window_seconds`; `on_ready` and `on_end` at the
// window's start and end.
DirectStateResult direct_state(const Run& run, double window_seconds, const StatePattern& pattern,
                               const std::function<void()>& on_ready,
                               const std::function<void()>& on_end);

}  // namespace dnbridge::bench
