// (0d) One thread of this process waking another on the same CPU, nothing
// else running: the one hand-over each of (1) and (2) makes.
#include <fmt/format.h>

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "bridge_bench.hpp"

namespace dnbridge::bench {
namespace {

// One thread waking another of the same process, on the CPU it runs on,
// with nothing else to do: the one hand-over each of the bridge's paths
// makes (a received frame to the port's thread, a command from Cyclone's
// thread to it), as the simulated bus makes it: a time stamped, a queue
// under a mutex, a condition variable. One every 250 us, `seconds` long.
// The best case: the waking thread sleeps right after, so the woken one has
// the CPU at once; in the bridge the waking thread goes on with its work.
std::vector<double> thread_handover(double seconds) {
  std::mutex mutex;
  std::condition_variable woken;
  std::vector<std::int64_t> queue;
  bool stop = false;
  std::vector<double> latencies;
  latencies.reserve(static_cast<std::size_t>(seconds * 4000) + 16);
  std::thread waiter([&] {
    std::vector<std::int64_t> taken;
    std::unique_lock lock(mutex);
    for (;;) {
      woken.wait(lock, [&] { return stop || !queue.empty(); });
      if (stop) return;
      taken.swap(queue);
      lock.unlock();
      const auto now = steady_ns();
      for (auto at : taken) latencies.push_back(static_cast<double>(now - at) / 1e3);
      taken.clear();
      lock.lock();
    }
  });
  const auto start = monotonic_ns();
  const auto end = start + static_cast<std::int64_t>(seconds * 1e9);
  for (auto next = start; next < end; next += 250'000) {
    sleep_until_monotonic(next);
    {
      std::lock_guard lock(mutex);
      queue.push_back(steady_ns());
    }
    woken.notify_one();
  }
  {
    std::lock_guard lock(mutex);
    stop = true;
  }
  woken.notify_one();
  waiter.join();
  return latencies;
}

}  // namespace

void measure_thread_handover(const Run& run) {
  const Summary h = summarize(thread_handover(std::min(run.options.direct_seconds, 5.0)));
  fmt::print(
      "(0d) a thread woken by another of this process {}, nothing else running\n"
      "     (a condition variable, one every 250 us; the waking thread then sleeps): the\n"
      "     hand-over each of the bridge's paths makes once, at its best\n"
      "     samples {}  p50 {}  p99 {}  max {}\n\n",
      run.cpus.tested >= 0 ? "on the same CPU" : "(both where the kernel puts them)", h.count,
      us(h.p50), us(h.p99), us(h.max));
}

}  // namespace dnbridge::bench
