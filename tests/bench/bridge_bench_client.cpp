// dnbridge-bench's client: this program re-executed with --client, another
// process and another DDS participant than the bridge's. It subscribes to
// every PumpState and, in the latency modes, commands the first port's
// nodes; it prints what it took and wrote for the benchmark to read.
#include <fmt/format.h>
#include <signal.h>

#include <atomic>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/time.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "bridge_bench.hpp"

namespace dnbridge::bench {
namespace {

// The subscriber and commander of one client process.
class Client {
 public:
  explicit Client(const ClientOptions& o)
      : o_(o),
        participant_(static_cast<dds_domainid_t>(o.domain), "bench-client"),
        state_topic_(participant_),
        command_topic_(participant_),
        reader_(participant_, state_topic_, dds::state_reader_qos()),
        writer_(participant_, command_topic_,
                dds::command_writer_qos(dds::rack_partitions(kRack), 10, seconds(5))),
        any_(reader_, DDS_ANY_STATE),
        stop_(participant_),
        waitset_(participant_),
        // "oneway": no bridge, only a reader of the commands to match.
        // "state": no bridge, PumpStates written by the benchmark with the
        // bridge's QoS, and no command reader to match.
        commanding_(o.mode == "latency" || o.mode == "oneway"),
        state_latency_(o.mode == "latency" || o.mode == "state"),
        command_reader_(o.mode != "state"),
        expected_(o.mode == "oneway" ? 0 : o.ports.size() * o.nodes),
        ready_(o.ports.size() * 64, 0),
        last_analog_(o.ports.size() * 64, -1) {
    waitset_.attach(any_, 1);
    waitset_.attach(stop_, 2);
    latencies_.reserve(200000);
  }
  ~Client() { stop_taking(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  int run() {
    taker_ = std::thread([this] { take_until_stopped(); });
    if (!wait_ready()) return fail("not every node came online within 90 s");
    std::printf("ready\n");
    std::fflush(stdout);
    const auto start = monotonic_ns();
    const auto window = static_cast<std::int64_t>(o_.seconds * 1e9);
    measuring_ = true;
    const bool written = commanding_ ? command_round_robin(start, window)
                                     : command_each_once_and_wait(start, window);
    if (!written) return fail("writing a PumpCommand failed");
    measuring_ = false;
    const auto elapsed = monotonic_ns() - start;
    stop_taking();
    print_records(elapsed);
    return 0;
  }

 private:
  // Each new poll response's sample: its latency, key and analog input
  // (with which the benchmark finds the response it came from).
  struct StateLatency {
    std::int64_t ns;
    std::size_t key;
    int analog;
  };
  struct Written {
    unsigned mac;
    unsigned value;
    std::int64_t at;
  };

  std::optional<std::size_t> key_of(const dnbridge_PumpState& s) const {
    for (std::size_t p = 0; p < o_.ports.size(); ++p) {
      if (dds::view(s.port) == o_.ports[p] && s.mac >= 1 && s.mac <= o_.nodes) {
        return p * 64 + s.mac;
      }
    }
    return std::nullopt;
  }

  // The taking thread.
  void take_until_stopped() {
    for (;;) {
      auto triggered = waitset_.wait(milliseconds(200));
      if (!triggered) continue;
      bool stopping = false;
      for (auto t : *triggered) stopping = stopping || t == 2;
      if (stopping) return;
      // Few at a time: Reader::take allocates `max` samples and frees the
      // unused ones, a cost that would be counted in the latency.
      auto samples = reader_.take(any_, 8);
      const auto now = dds::dds_now();
      if (!samples) continue;
      const bool counting = measuring_.load(std::memory_order_relaxed);
      for (const auto& s : *samples) note(s, now, counting);
    }
  }

  // On the taking thread: one sample taken at `now`.
  void note(const dds::Sample<dnbridge_PumpState>& s, dds::Timestamp now, bool counting) {
    if (!s.valid_data()) return;
    const auto& d = s.data();
    const auto key = key_of(d);
    if (!key) return;
    const bool is_ready = d.online && d.inputs_valid;
    if (is_ready != static_cast<bool>(ready_[*key])) {
      ready_[*key] = is_ready;
      ready_n_ = is_ready ? ready_n_ + 1 : ready_n_ - 1;
      ready_count_.store(ready_n_);
    }
    const int analog = d.analog_input_count > 0 ? d.analog_input_raw[0] : -1;
    const bool fresh = analog != last_analog_[*key];
    last_analog_[*key] = analog;
    if (!counting) return;
    taken_.fetch_add(1, std::memory_order_relaxed);
    // A new analog value: the sample of a new poll response.
    if (state_latency_ && is_ready && fresh) {
      latencies_.push_back({(now - s.info().source_timestamp()).count(), *key, analog});
    }
  }

  // Every node online and its inputs read, and the bridge's command reader
  // matched, within 90 s.
  bool wait_ready() {
    const auto online_deadline = monotonic_ns() + 90'000'000'000;
    while (ready_count_.load() < expected_ ||
           (command_reader_ && writer_.matched_subscriptions().value_or(0) == 0)) {
      if (monotonic_ns() > online_deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  }

  bool command(const std::string& port, unsigned mac, bool pump_on, unsigned value) {
    dds::Owned<dnbridge_PumpCommand> c;
    dds::set_string(c->rack, kRack);
    dds::set_string(c->port, port);
    c->mac = static_cast<std::uint8_t>(mac);
    c->pump_on = pump_on;
    c->n2_ballast_on = false;
    c->analog_output_raw = static_cast<std::uint16_t>(value);
    dds::set_string(c->issuer, "dnbridge-bench");
    // The write time, on CLOCK_MONOTONIC; the sample's source timestamp is
    // Cyclone's wall clock at the same moment.
    const auto at = monotonic_ns();
    if (!writer_.write(*c)) return false;
    written_.push_back({mac, value, at});
    return true;
  }

  // Round robin over the nodes of the first port; each command a new analog
  // output value for its node (1..4095), so that the poll frame that carries
  // it is known by its value. The gaps are drawn uniformly from 0.5..1.5 x
  // the interval (fixed seed): commands at a fixed period would meet the
  // bridge's poll schedule, which has the same period, at one phase for the
  // whole run, and measure that phase only.
  bool command_round_robin(std::int64_t start, std::int64_t window) {
    std::vector<unsigned> value(64, 0);
    const auto interval = static_cast<std::int64_t>(o_.command_interval_us) * 1000;
    std::mt19937_64 random(20261122);
    std::uniform_int_distribution<std::int64_t> gap(interval / 2, interval + interval / 2);
    std::int64_t next = start;
    for (unsigned i = 0; monotonic_ns() < start + window; ++i) {
      const unsigned mac = 1 + i % o_.nodes;
      value[mac] = value[mac] % 4095 + 1;
      if (!command(o_.ports[0], mac, false, value[mac])) return false;
      next += gap(random);
      sleep_until_monotonic(next);
    }
    sleep_until_monotonic(monotonic_ns() + 300'000'000);  // the last commands' polls
    return true;
  }

  // With --command-once, one command per node at the start; then the window.
  bool command_each_once_and_wait(std::int64_t start, std::int64_t window) {
    if (o_.command_once) {
      for (const auto& port : o_.ports) {
        for (unsigned mac = 1; mac <= o_.nodes; ++mac) {
          if (!command(port, mac, true, 2048)) return false;
        }
      }
    }
    sleep_until_monotonic(start + window);
    return true;
  }

  void stop_taking() {
    if (!taker_.joinable()) return;
    (void)stop_.trigger();
    taker_.join();
  }

  int fail(const char* what) {
    std::fprintf(stderr, "dnbridge-bench client: %s\n", what);
    stop_taking();
    return 1;
  }

  // "taken" first: the benchmark ends a CPU window on it, before it reads
  // the rest.
  void print_records(std::int64_t elapsed) const {
    std::string out;
    out.reserve(latencies_.size() * 24 + written_.size() * 32 + 256);
    out += fmt::format("taken {} {}\n", taken_.load(), elapsed);
    for (const auto& l : latencies_) {
      out += fmt::format("state {} {} {}\n", l.ns, l.key, l.analog);
    }
    if (commanding_) {
      for (const auto& w : written_) out += fmt::format("cmd {} {} {}\n", w.mac, w.value, w.at);
    }
    out += "done\n";
    std::fwrite(out.data(), 1, out.size(), stdout);
    std::fflush(stdout);
  }

  const ClientOptions& o_;
  dds::Participant participant_;
  dds::Topic<dnbridge_PumpState> state_topic_;
  dds::Topic<dnbridge_PumpCommand> command_topic_;
  dds::Reader<dnbridge_PumpState> reader_;
  dds::Writer<dnbridge_PumpCommand> writer_;
  dds::ReadCondition any_;
  dds::GuardCondition stop_;
  dds::WaitSet waitset_;
  const bool commanding_;
  const bool state_latency_;
  const bool command_reader_;
  const std::size_t expected_;

  std::atomic<std::size_t> ready_count_{0};
  std::atomic<bool> measuring_{false};
  std::atomic<std::uint64_t> taken_{0};
  // The taking thread's, until it is joined.
  std::vector<char> ready_;
  std::vector<int> last_analog_;
  std::size_t ready_n_ = 0;
  std::vector<StateLatency> latencies_;
  // The main thread's.
  std::vector<Written> written_;
  std::thread taker_;
};

// One line of a client's output but "ready" and "done".
void parse_client_line(const std::string& line, ClientOutput& out,
                       const std::function<void()>& on_end) {
  if (line.rfind("state ", 0) == 0) {
    long long ns = 0;
    std::size_t key = 0;
    int value = -1;
    if (std::sscanf(line.c_str(), "state %lld %zu %d", &ns, &key, &value) == 3) {
      out.state_us.push_back(static_cast<double>(ns) / 1e3);
      if (value >= 0)
        out.states.push_back({out.state_us.back(), key, static_cast<unsigned>(value)});
    }
  } else if (line.rfind("cmd ", 0) == 0) {
    ClientOutput::Cmd c{};
    long long at = 0;
    if (std::sscanf(line.c_str(), "cmd %u %u %lld", &c.mac, &c.value, &at) == 3) {
      c.at = at;
      out.commands.push_back(c);
    }
  } else if (line.rfind("taken ", 0) == 0) {
    on_end();
    unsigned long long n = 0;
    long long ns = 0;
    if (std::sscanf(line.c_str(), "taken %llu %lld", &n, &ns) == 2) {
      out.taken = n;
      out.window_s = static_cast<double>(ns) / 1e9;
    }
  }
}

}  // namespace

int run_client(const ClientOptions& o) {
  Client client(o);
  return client.run();
}

std::vector<std::string> client_args(const std::string& mode, int domain,
                                     const std::vector<std::string>& ports, unsigned nodes,
                                     double seconds) {
  std::string port_list;
  for (const auto& p : ports) port_list += (port_list.empty() ? "" : ",") + p;
  return {"/proc/self/exe",
          "--client",
          mode,
          "--domain",
          std::to_string(domain),
          "--ports",
          port_list,
          "--nodes",
          std::to_string(nodes),
          "--seconds",
          fmt::format("{}", seconds)};
}

ClientOutput read_client(Child child, double seconds, const std::function<void()>& on_ready,
                         const std::function<void()>& on_end) {
  ClientOutput out;
  const auto deadline = monotonic_ns() + static_cast<std::int64_t>((seconds + 150) * 1e9);
  read_child_output(child, deadline, "client", [&](const std::string& line) {
    if (line == "ready") {
      on_ready();
    } else {
      parse_client_line(line, out, on_end);
    }
  });
  return out;
}

}  // namespace dnbridge::bench
