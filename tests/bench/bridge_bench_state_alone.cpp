// (0c) Cyclone DDS alone on the state path: PumpStates written in this
// process with the bridge's QoS, in the pattern of (1)'s poll responses,
// taken by the subscriber process as in (1); the bridge's own addition to
// (1) is measured against it. (3c) and (3d) write (3b)'s samples the same
// way, for their CPU time.
#include <dds/dds.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <stdexcept>
#include <thread>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "bridge_bench.hpp"

namespace dnbridge::bench {
namespace {

std::int64_t ns(Duration d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

// Cyclone's write batching, on for as long as this lives when asked for.
struct Batching {
  explicit Batching(bool enable) : on(enable) {
    if (on) dds_write_set_batch(true);
  }
  ~Batching() {
    if (on) dds_write_set_batch(false);
  }
  Batching(const Batching&) = delete;
  Batching& operator=(const Batching&) = delete;
  bool on;
};

// The writer of a StatePattern: every instance written once at its
// creation, then, between start() and end(), at the pattern's pace from a
// thread of its own.
class StatePacer {
 public:
  StatePacer(int domain, const StatePattern& p)
      : p_(p),
        participant_(static_cast<dds_domainid_t>(domain), kRack),
        topic_(participant_),
        writer_(participant_, topic_, dds::state_writer_qos(seconds(2))),
        batching_(p.batched),
        states_(p.ports.size() * p.nodes),
        per_batch_((states_.size() + p.batches - 1) / p.batches) {
    for (std::size_t i = 0; i < states_.size(); ++i) {
      auto& st = states_[i];
      dds::set_string(st->rack, kRack);
      dds::set_string(st->port, p.ports[i / p.nodes]);
      st->mac = static_cast<std::uint8_t>(1 + i % p.nodes);
      dds::set_string(st->name, fmt::format("pump-{}-{}", p.ports[i / p.nodes], st->mac));
      dds::set_string(st->idle_reason, "");
      st->online = st->inputs_valid = true;
      st->analog_input_count = 1;
      if (!writer_.write(*st)) throw std::runtime_error("writing a PumpState failed");
    }
  }
  ~StatePacer() { stop(); }
  StatePacer(const StatePacer&) = delete;
  StatePacer& operator=(const StatePacer&) = delete;

  // The window's start: its clocks read, the writing begun.
  void start() {
    wall0_ = monotonic_ns();
    cpu0_ = process_cpu_ns();
    pace_ = std::thread([this] { pace(); });
  }

  // The window's end: its figures into `r`, the writing told to stop.
  void end(DirectStateResult& r) {
    r.window_s = static_cast<double>(monotonic_ns() - wall0_) / 1e9;
    r.process_cpu_s = static_cast<double>(process_cpu_ns() - cpu0_) / 1e9;
    r.write_cpu_s = static_cast<double>(write_cpu_ns_.load()) / 1e9;
    r.written = written_.load();
    stop_ = true;
  }

  void stop() {
    stop_ = true;
    if (pace_.joinable()) pace_.join();
  }

 private:
  void pace() {
    std::int64_t cycle = monotonic_ns();
    while (!stop_.load(std::memory_order_relaxed)) {
      for (unsigned b = 0; b < p_.batches; ++b) {
        sleep_until_monotonic(cycle + b * ns(p_.spacing));
        write_batch(b);
      }
      cycle += ns(p_.period);
    }
  }

  // Batch `b`, each instance with a new analog value; the thread's CPU time
  // in it counted.
  void write_batch(unsigned b) {
    const auto t0 = clock_ns(CLOCK_THREAD_CPUTIME_ID);
    const auto first = b * per_batch_;
    for (auto i = first; i < std::min(first + per_batch_, states_.size()); ++i) {
      auto& st = *states_[i];
      st.analog_input_raw[0] = static_cast<std::uint16_t>((st.analog_input_raw[0] + 1) % 4096);
      (void)writer_.write(st);
      written_.fetch_add(1, std::memory_order_relaxed);
    }
    if (p_.batched) (void)dds_write_flush(writer_.handle());
    write_cpu_ns_.fetch_add(clock_ns(CLOCK_THREAD_CPUTIME_ID) - t0, std::memory_order_relaxed);
  }

  const StatePattern& p_;
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpState> topic_;
  dds::Writer<dnbridge_PumpState> writer_;
  Batching batching_;
  std::vector<dds::Owned<dnbridge_PumpState>> states_;
  const std::size_t per_batch_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> write_cpu_ns_{0};
  std::atomic<std::uint64_t> written_{0};
  std::int64_t cpu0_ = 0, wall0_ = 0;
  std::thread pace_;
};

}  // namespace

DirectStateResult direct_state(const Run& run, double window_seconds, const StatePattern& pattern,
                               const std::function<void()>& on_ready,
                               const std::function<void()>& on_end) {
  StatePacer pacer(run.domain, pattern);
  DirectStateResult r;
  const auto args = client_args("state", run.domain, pattern.ports, pattern.nodes, window_seconds);
  ClientOutput out = read_client(
      spawn_child(args, true, run.cpus.peer), window_seconds,
      [&] {
        pacer.start();
        on_ready();
      },
      [&] {
        pacer.end(r);
        on_end();
      });
  pacer.stop();
  r.latency_us = std::move(out.state_us);
  r.taken = out.taken;
  return r;
}

std::optional<Summary> measure_state_path_alone(const Run& run, int poll_ms) {
  const Options& o = run.options;
  // In the pattern of this run's poll responses: each node once per poll
  // period, one response frame time, about 250 us at 500 kbit/s, apart.
  fmt::print(
      "(0c) Cyclone DDS alone on the state path: PumpStates written in this process with "
      "the\n     bridge's QoS, {} instances every {} ms 250 us apart, each a new analog "
      "value, taken by\n     the subscriber process as in (1); wall clock at take - source "
      "timestamp ({} s) ...\n",
      o.latency_nodes, poll_ms, o.direct_seconds);
  std::fflush(stdout);
  DdsperfBeside ddsperf(run);
  const StatePattern pattern{
      {"A"}, o.latency_nodes, milliseconds(poll_ms), o.latency_nodes, microseconds(250)};
  const auto r = direct_state(
      run, o.direct_seconds, pattern, [&] { ddsperf.start(o.direct_seconds); }, [] {});
  const Reference ref = ddsperf.report();
  const Summary d = summarize(r.latency_us);
  fmt::print("(0c) write -> take, one way: samples {}  p50 {}  p99 {}  max {}\n", d.count,
             us(d.p50), us(d.p99), us(d.max));
  fmt::print("     ratio to ddsperf's one-way:  p50 {:.2f}  p99 {:.2f}\n\n", d.p50 / ref.p50,
             d.p99 / ref.p99);
  if (d.count > 0) return d;
  return std::nullopt;
}

}  // namespace dnbridge::bench
