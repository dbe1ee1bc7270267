// (0) Cyclone DDS's own one-way latency: ddsperf ping and pong (two
// processes, waitset mode, on loopback), run beside each latency measurement
// over the same seconds, on the same CPUs; one-way = round trip / 2 (ddsperf
// prints its round trips halved already).
#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "bridge_bench.hpp"

namespace dnbridge::bench {

void DdsperfBeside::start(double seconds) {
  const Options& o = run_.options;
  ddsperf_.emplace(run_.domain, seconds, o.ddsperf_rate, o.ddsperf_size, run_.cpus);
}

Reference DdsperfBeside::report() {
  if (!ddsperf_) throw std::runtime_error("the measurement ended before it started");
  const DdsperfResult cyc = ddsperf_->finish();
  ddsperf_.reset();
  double window_p99_lo = cyc.windows.front().p99, window_p99_hi = window_p99_lo;
  for (const auto& w : cyc.windows) {
    window_p99_lo = std::min(window_p99_lo, w.p99);
    window_p99_hi = std::max(window_p99_hi, w.p99);
  }
  fmt::print("(0) Cyclone DDS, beside it: ddsperf {}(and ddsperf pong waitset)\n", cyc.command);
  fmt::print(
      "    one-way = round trip / 2 (as ddsperf prints it), {:.0f} round trips in {} one-second\n"
      "    windows (the first left out):  p50 {}  p99 {}  max {}\n"
      "    (p99 of single windows {:.1f}..{:.1f} us)\n",
      cyc.samples, cyc.windows.size(), us(cyc.half_rtt_p50), us(cyc.half_rtt_p99),
      us(cyc.half_rtt_max), window_p99_lo, window_p99_hi);
  return Reference{cyc.half_rtt_p50, cyc.half_rtt_p99};
}

}  // namespace dnbridge::bench
