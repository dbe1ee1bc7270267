#pragma once
// Cyclone DDS's own latency as its ddsperf tool measures it (ping and pong,
// two processes), for the benchmarks to print beside their own figures.
#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <regex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bench_process.hpp"

namespace dnbridge::bench {

// What ddsperf ping prints of a round trip is already half of it: it
// records (time the pong is taken - the ping's source timestamp) / 2 (Cyclone
// DDS 0.10.2, src/tools/ddsperf/ddsperf.c, process_pong). Its figures are
// therefore Cyclone's one-way latency as a halved round trip, as printed.
struct DdsperfWindow {
  double min, p50, p90, p99, max;  // half round trip, us
  double count;
};

struct DdsperfResult {
  std::vector<DdsperfWindow> windows;  // the first (warm-up) window left out
  double half_rtt_p50 = 0, half_rtt_p99 = 0, half_rtt_max = 0;  // us
  double samples = 0;
  std::string command;
};

// ddsperf prints, once a second, the halved round trips of that second: mean,
// min, 50 %, 90 %, 99 %, max and count; it prints no figure over the whole run.
// The run's percentiles are computed from the windows: each window's
// distribution is taken as piecewise linear between its reported quantiles,
// the windows are pooled weighted by their counts, and the pooled
// distribution is inverted.
inline double pooled_quantile(const std::vector<DdsperfWindow>& ws, double q) {
  auto window_cdf = [](const DdsperfWindow& w, double x) {
    const std::array<double, 5> xs{w.min, w.p50, w.p90, w.p99, w.max};
    const std::array<double, 5> qs{0.0, 0.5, 0.9, 0.99, 1.0};
    if (x < xs[0]) return 0.0;
    if (x >= xs[4]) return 1.0;
    for (std::size_t i = 1; i < xs.size(); ++i) {
      if (x < xs[i]) {
        const double span = xs[i] - xs[i - 1];
        return span > 0 ? qs[i - 1] + (qs[i] - qs[i - 1]) * (x - xs[i - 1]) / span : qs[i];
      }
    }
    return 1.0;
  };
  double lo = ws.front().min, hi = ws.front().max, total = 0;
  for (const auto& w : ws) {
    lo = std::min(lo, w.min);
    hi = std::max(hi, w.max);
    total += w.count;
  }
  for (int i = 0; i < 100; ++i) {
    const double mid = (lo + hi) / 2;
    double f = 0;
    for (const auto& w : ws) f += w.count * window_cdf(w, mid);
    (f / total < q ? lo : hi) = mid;
  }
  return hi;
}

// Which CPU the measured process (the bridge; ddsperf pong) and its peer (the
// subscriber and commander; ddsperf ping) run on; -1: wherever the kernel
// puts them.
struct Placement {
  int tested = -1;
  int peer = -1;
};

// With `pin`, this process (every thread it starts later too) on CPU
// `tested_cpu`, and the returned Placement names `peer_cpu` for the peer;
// without, or when the two are not distinct online CPUs, no placement.
// Prints which; throws when this process cannot be pinned.
inline Placement place_processes(bool pin, int tested_cpu, int peer_cpu, std::string_view tested,
                                 std::string_view peer) {
  const int online = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  if (!pin || tested_cpu == peer_cpu || std::max(tested_cpu, peer_cpu) >= online ||
      std::min(tested_cpu, peer_cpu) < 0) {
    fmt::print("CPUs: every process and thread where the kernel puts it{}\n\n",
               pin ? " (two distinct online CPUs are needed to pin)" : "");
    return {};
  }
  if (!pin_to_cpu(tested_cpu)) {
    throw std::runtime_error(fmt::format("cannot keep the benchmark on CPU {}", tested_cpu));
  }
  fmt::print("CPUs: {} and ddsperf pong on CPU {}; {} and ddsperf ping on CPU {}\n\n", tested,
             tested_cpu, peer, peer_cpu);
  return {tested_cpu, peer_cpu};
}

// ddsperf ping and pong, run beside a measurement of the bridge: started when
// the measurement starts, read when it ends, so that both see the same
// machine at the same time.
class Ddsperf {
 public:
  Ddsperf(int domain, double seconds, int rate_hz, int size, Placement cpus) {
    const std::string d = std::to_string(domain);
    const auto run_s = static_cast<int>(std::ceil(seconds)) + 2;
    // pong outlives ping; ping waits (initwait) for its pong before it starts.
    pong_ = spawn_child({"ddsperf", "-i", d, "-D", std::to_string(run_s + 15), "pong", "waitset"},
                        false, cpus.tested);
    std::vector<std::string> ping_args{"ddsperf",
                                       "-i",
                                       d,
                                       "-Qminmatch:1",
                                       "-Qinitwait:10",
                                       "-D",
                                       std::to_string(run_s),
                                       "ping",
                                       std::to_string(rate_hz) + "Hz",
                                       "size",
                                       std::to_string(size),
                                       "waitset"};
    for (std::size_t i = 1; i < ping_args.size(); ++i) command_ += ping_args[i] + " ";
    ping_ = spawn_child(ping_args, true, cpus.peer);
    deadline_ = monotonic_ns() + static_cast<std::int64_t>((run_s + 30) * 1e9);
  }
  Ddsperf(const Ddsperf&) = delete;
  Ddsperf& operator=(const Ddsperf&) = delete;
  ~Ddsperf() {
    if (ping_.pid > 0) {
      kill(ping_.pid, SIGKILL);
      (void)wait_child(ping_.pid);
      close(ping_.out);
    }
    if (pong_.pid > 0) {
      kill(pong_.pid, SIGKILL);
      (void)wait_child(pong_.pid);
    }
  }

  // Reads ping's report to its end (the run's length) and stops pong.
  DdsperfResult finish() {
    DdsperfResult r;
    r.command = command_;
    LineReader lines(ping_.out);
    const std::regex re(
        R"(size \d+ mean [\d.]+us min ([\d.]+)us 50% ([\d.]+)us 90% ([\d.]+)us 99% ([\d.]+)us max ([\d.]+)us cnt (\d+))");
    bool first = true;
    while (auto line = lines.next(deadline_)) {
      std::smatch m;
      if (!std::regex_search(*line, m, re)) continue;
      if (first) {  // discovery and warm-up
        first = false;
        continue;
      }
      r.windows.push_back({std::stod(m[1]), std::stod(m[2]), std::stod(m[3]), std::stod(m[4]),
                           std::stod(m[5]), std::stod(m[6])});
    }
    close(ping_.out);
    if (lines.timed_out()) kill(ping_.pid, SIGKILL);
    const int ping_status = wait_child(ping_.pid);
    ping_.pid = -1;
    kill(pong_.pid, SIGTERM);
    (void)wait_child(pong_.pid);
    pong_.pid = -1;
    if (ping_status != 0 || r.windows.empty()) {
      throw std::runtime_error(
          fmt::format("ddsperf ping failed (exit {}, {} windows)", ping_status, r.windows.size()));
    }
    for (const auto& w : r.windows) {
      r.samples += w.count;
      r.half_rtt_max = std::max(r.half_rtt_max, w.max);
    }
    r.half_rtt_p50 = pooled_quantile(r.windows, 0.50);
    r.half_rtt_p99 = pooled_quantile(r.windows, 0.99);
    return r;
  }

 private:
  Child pong_, ping_;
  std::string command_;
  std::int64_t deadline_ = 0;
};

}  // namespace dnbridge::bench
