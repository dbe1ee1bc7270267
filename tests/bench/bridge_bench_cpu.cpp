// (3) CPU time of the bridge per second of wall time, 4 ports x 63 nodes
// polled every 10 ms, the simulated devices' threads left out; (3b) the same
// with a PumpState per poll; (3c) Cyclone alone writing (3b)'s samples, CPU
// per sample, which splits (3b)'s cost per sample into Cyclone's write and
// the bridge's own work; (3d) (3c) with Cyclone's write batching.
#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

#include "bridge_bench.hpp"
#include "bridge_bench_bridge.hpp"

namespace dnbridge::bench {
namespace {

struct CpuFigures {
  double bridge_pct;     // of one core
  double samples_per_s;  // PumpState taken by the subscriber
};

// The bridge's counters, and this process's threads, at one edge of a window.
struct CpuCounters {
  std::int64_t wall = 0, cpu = 0, sim = 0;
  std::uint64_t polls = 0, responses = 0, bits = 0;
  ProcessSample threads;
};

CpuCounters read_counters(const Bridge& bridge) {
  CpuCounters c;
  c.wall = monotonic_ns();
  c.cpu = process_cpu_ns();
  c.sim = bridge.sim_cpu_ns();
  c.polls = bridge.polls();
  c.responses = bridge.responses();
  c.bits = bridge.bus_bits();
  c.threads = sample_process(getpid());
  return c;
}

// One CPU window of the bridge under the client.
struct CpuWindow {
  double online_s = 0;  // until every node was online
  CpuCounters from, to;
  std::set<pid_t> port_tids, sim_tids;
  ClientOutput out;
};

CpuWindow run_cpu_window(const Run& run, const BridgeSetup& s, double window) {
  Bridge bridge(s, run.domain, run.log);
  bridge.start();
  CpuWindow w;
  const auto online_from = monotonic_ns();
  auto args = client_args("count", run.domain, s.ports, s.nodes, window);
  args.push_back("--command-once");
  w.port_tids = bridge.port_threads();
  w.sim_tids = bridge.sim_threads();
  const auto start = [&] {
    w.online_s = static_cast<double>(monotonic_ns() - online_from) / 1e9;
    w.from = read_counters(bridge);
  };
  // The client has taken samples for `window` seconds since it said ready,
  // and is still subscribed and commanding.
  const auto end = [&] { w.to = read_counters(bridge); };
  w.out = read_client(spawn_child(args, true, run.cpus.peer), window, start, end);
  bridge.stop();
  return w;
}

// The window's CPU time by thread, in groups.
void print_thread_groups(const CpuWindow& w, double wall) {
  struct Group {
    const char* name;
    double cpu_s = 0;
    double switches = 0;
    unsigned threads = 0;
  };
  // The bridge's threads by their names (adapters/daemon: the reply
  // outbox, the DDS input; the port loops write the state samples);
  // Cyclone's by elimination.
  std::array<Group, 6> groups{{{"port loops"},
                               {"reply outbox"},
                               {"DDS input"},
                               {"main and other"},
                               {"Cyclone DDS's own"},
                               {"simulated devices"}}};
  const auto group_of = [&](pid_t tid, const std::string& name) -> Group& {
    if (w.port_tids.count(tid)) return groups[0];
    if (w.sim_tids.count(tid)) return groups[5];
    if (name == "dds reply out") return groups[1];
    if (name == "dds input") return groups[2];
    if (name.rfind("dnbridge-ben", 0) == 0 || name == "reload" || name == "sd_notify") {
      return groups[3];
    }
    return groups[4];
  };
  for (const auto& [tid, t1] : w.to.threads.threads) {
    auto it = w.from.threads.threads.find(tid);
    if (it == w.from.threads.threads.end()) continue;
    Group& g = group_of(tid, t1.name);
    g.cpu_s += ticks_seconds(t1.ticks - it->second.ticks);
    g.switches += static_cast<double>(t1.switches - it->second.switches);
    ++g.threads;
  }
  fmt::print("    by thread (/proc, 10 ms ticks):");
  for (const auto& g : groups) {
    fmt::print(" {} ({}) {:.1f} %, {:.0f} switches/s;", g.name, g.threads, 100.0 * g.cpu_s / wall,
               g.switches / wall);
  }
  fmt::print("\n");
}

// 4 ports x 63 CDN127s on an ideal bus, every PumpState taken by the client;
// with `every_poll`, every poll response a new analog input, published.
CpuFigures cpu_run(const Run& run, const char* title, double window, bool every_poll) {
  BridgeSetup s;
  s.ports = {"P1", "P2", "P3", "P4"};
  s.nodes = 63;
  s.bitrate = 0;  // ideal bus: see the bus load printed below
  s.publish = every_poll ? rack::PublishPolicy{seconds(1), 0.0} : rack::PublishPolicy{};
  s.ramp = every_poll;
  fmt::print("{}\n", title);
  std::fflush(stdout);
  const CpuWindow w = run_cpu_window(run, s, window);
  const double wall = static_cast<double>(w.to.wall - w.from.wall) / 1e9;
  if (wall <= 0) throw std::runtime_error("the CPU window was not measured");
  const double cpu = static_cast<double>(w.to.cpu - w.from.cpu) / 1e9;
  const double sim_cpu = static_cast<double>(w.to.sim - w.from.sim) / 1e9;
  const auto polls = static_cast<double>(w.to.polls - w.from.polls);
  const auto responses = static_cast<double>(w.to.responses - w.from.responses);
  const auto bits = static_cast<double>(w.to.bits - w.from.bits);
  const double bridge_pct = 100.0 * (cpu - sim_cpu) / wall;
  fmt::print("    all {} nodes online after {:.1f} s; measured over {:.1f} s of wall time\n",
             s.ports.size() * s.nodes, w.online_s, wall);
  fmt::print(
      "    polls {:.0f}/s (expected {:.0f}/s), poll responses {:.0f}/s, PumpState samples "
      "taken by the subscriber {:.0f}/s\n",
      polls / wall, static_cast<double>(s.ports.size() * s.nodes) * 100.0, responses / wall,
      static_cast<double>(w.out.taken) / w.out.window_s);
  fmt::print("    bus: {:.0f} bit/s per port, {:.0f} % of a 500 kbit/s bus: hence the ideal bus\n",
             bits / wall / 4, 100.0 * bits / wall / 4 / 500000.0);
  fmt::print(
      "    CPU: process {:.1f} %, simulated devices' threads {:.1f} %, bridge {:.1f} % of "
      "one core\n",
      100.0 * cpu / wall, 100.0 * sim_cpu / wall, bridge_pct);
  print_thread_groups(w, wall);
  return CpuFigures{bridge_pct, static_cast<double>(w.out.taken) / w.out.window_s};
}

// (3c), (3d): CPU per sample written, in the write calls and of the process.
double write_cost(const Run& run, const StatePattern& p) {
  const auto r = direct_state(
      run, run.options.busy_seconds, p, [] {}, [] {});
  if (r.written == 0 || r.window_s <= 0) throw std::runtime_error("(3c) wrote nothing");
  const double n = static_cast<double>(r.written);
  const double write_us = r.write_cpu_s / n * 1e6;
  const double process_us = r.process_cpu_s / n * 1e6;
  fmt::print(
      "    written {:.0f}/s, taken {:.0f}/s; CPU per sample: {:.2f} us in the write calls{}, "
      "{:.2f} us\n     for this process in all (Cyclone's own threads included; {:.1f} % of "
      "one core)\n",
      n / r.window_s, static_cast<double>(r.taken) / r.window_s, write_us,
      p.batched ? " and flushes" : "", process_us, 100.0 * r.process_cpu_s / r.window_s);
  return process_us;
}

// (3b) to (3d), after (3) gave `shipped`.
void measure_busy_cpu(const Run& run, const CpuFigures& shipped) {
  const CpuFigures busy = cpu_run(
      run,
      "(3b) the same, but every poll response a new analog input and deadband 0: a PumpState "
      "per poll ...",
      run.options.busy_seconds, true);
  fmt::print("\n");
  // (3c): what Cyclone's writes of (3b)'s samples cost, alone.
  fmt::print(
      "(3c) Cyclone DDS alone writing (3b)'s samples: PumpStates of 4 x 63 instances, each "
      "every\n     10 ms, in batches every 1 ms, written in this process with the bridge's "
      "QoS, taken by\n     the subscriber process ...\n");
  std::fflush(stdout);
  StatePattern pattern{{"P1", "P2", "P3", "P4"}, 63, milliseconds(10), 10, milliseconds(1)};
  const double process_us = write_cost(run, pattern);
  // (3b) against (3): the CPU each further published sample costs the
  // bridge, and Cyclone's share of it.
  const double extra = busy.samples_per_s - shipped.samples_per_s;
  if (extra > 0) {
    const double per_sample_us = (busy.bridge_pct - shipped.bridge_pct) / 100.0 / extra * 1e6;
    fmt::print(
        "    (3b) - (3): {:.2f} us of the bridge's CPU per further PumpState published; of "
        "it Cyclone's\n     write {:.2f} us (3c), the bridge's own work {:.2f} us\n",
        per_sample_us, process_us, per_sample_us - process_us);
  }
  fmt::print(
      "(3d) the same as (3c) with Cyclone's write batching (dds_write_set_batch; a flush after "
      "each\n     batch: its samples leave together) ...\n");
  std::fflush(stdout);
  pattern.batched = true;
  (void)write_cost(run, pattern);
  fmt::print("\n");
}

}  // namespace

void measure_cpu(const Run& run) {
  const CpuFigures shipped = cpu_run(
      run,
      "(3) CPU: 4 ports x 63 CDN127s, each polled every 10 ms, on an ideal bus (no bit timing);\n"
      "    publish policy as shipped (on change, 0.05 V deadband, at least once a second); a\n"
      "    subscriber in another process takes every PumpState; one PumpCommand per pump at the "
      "start ...",
      run.options.cpu_seconds, false);
  fmt::print("    target < 10 % of one core: {}\n\n", verdict(shipped.bridge_pct < 10.0));
  if (run.options.busy_seconds > 0) measure_busy_cpu(run, shipped);
}

}  // namespace dnbridge::bench
