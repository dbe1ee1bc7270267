// dnbridge-fleet-bench: many racks on one DDS domain. For each fleet size N
// (--racks, default 1, 10, 50 and 100), N bridges (dnbridge-sim processes), each
// its own rack "fleet-K" of 63 simulated CDN127s on one port, polled every
// --poll-ms; then a supervisor (a participant of this process) joins the
// domain. Figures:
//   - how long until the supervisor has seen every PumpState instance
//     (N x 63), and every one online;
//   - per bridge, over --window-seconds once all are online: CPU (utime +
//     stime of the process, the simulated devices included) and RSS;
//   - bytes per second on the loopback interface over the window
//     (/proc/net/dev, received: all of it, which is the fleet's DDS traffic
//     on an otherwise idle host, discovery's announcements to participant
//     indices nobody has included, and the kernel's ICMP answers to those);
//   - `dnbctl racks --json` run once: its wall time, and how many racks it
//     found;
//   - the supervisor commanding pumps, --command-rate commands per second
//     in all, round robin over the racks (each command toggling its pump),
//     over a window each way, opened 2 s after its writers matched:
//     with a writer per rack in its rack's partition (as shipped), and with
//     one writer in every rack's partition ("dnbridge/*": each bridge then
//     receives every rack's commands and drops the others', as all bridges
//     did before racks had partitions). Per bridge CPU, the loopback's
//     bytes, the supervisor's own CPU, and the CPU of the bridges and the
//     supervisor together (how near the machine is to saturation), and how
//     many of the pumps commanded PumpState showed applied, each way.
// Every participant is on the loopback interface with unicast discovery and
// a discovery tag of the run's own. It reports figures; it exits non-zero
// only when the run itself fails.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "bench_process.hpp"
#include "figures.hpp"

namespace dnbridge::bench {
namespace {

constexpr unsigned kNodesPerRack = 63;  // MACs 1..63; the master is 0

struct Options {
  std::string dnbridge = DNBRIDGE_EXECUTABLE;
  std::string dnbctl = DNBCTL_EXECUTABLE;
  std::vector<int> racks{1, 10, 50, 100};
  int poll_ms = 1000;
  double window_seconds = 10;
  int command_rate = 200;
  double online_timeout_seconds = 180;
  int domain = -1;
};

// Rack `rack` of `nodes` simulated CDN127s on port A, on `domain`: the
// embedded default's settings but for the rack, the domain, the poll period
// and the nodes.
std::string rack_config(const std::string& default_text, const std::string& rack, int domain,
                        int poll_ms) {
  std::string text = default_text;
  const auto replace = [&](const std::string& pattern, const std::string& with) {
    const std::regex re(pattern, std::regex::multiline);
    if (!std::regex_search(text, re)) {
      throw std::runtime_error("the default configuration has no line " + pattern);
    }
    text = std::regex_replace(text, re, with);
  };
  replace(R"(^rack = .*$)", fmt::format("rack = \"{}\"", rack));
  replace(R"(^domain = \d+$)", fmt::format("domain = {}", domain));
  replace(R"(^log_level = .*$)", "log_level = \"warn\"");
  replace(R"(^poll_period_ms = \d+$)", fmt::format("poll_period_ms = {}", poll_ms));
  replace(R"(^expected_packet_rate_ms = \d+$)",
          fmt::format("expected_packet_rate_ms = {}", std::max(500, 2 * poll_ms)));
  // Its nodes replaced by 1..kNodesPerRack.
  const auto first_node = text.find("[[port.node]]");
  if (first_node == std::string::npos) throw std::runtime_error("no [[port.node]] in the default");
  text.erase(first_node);
  for (unsigned mac = 1; mac <= kNodesPerRack; ++mac) {
    text += fmt::format("[[port.node]]\nmac = {}\nname = \"pump-{}\"\n\n", mac, mac);
  }
  return text;
}

// Bytes received on the loopback interface so far (/proc/net/dev).
std::uint64_t loopback_bytes() {
  std::ifstream f("/proc/net/dev");
  std::string line;
  while (std::getline(f, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    name.erase(0, name.find_first_not_of(' '));
    if (name != "lo") continue;
    std::istringstream in(line.substr(colon + 1));
    std::uint64_t bytes = 0;
    in >> bytes;
    return bytes;
  }
  return 0;
}

// A window's figures.
struct WindowFigures {
  double cpu_mean = 0, cpu_max = 0;  // % of one core, per bridge
  double cpu_all = 0;                // % of one core, every bridge and the supervisor
  double rss_mean_kb = 0, rss_max_kb = 0;
  double lo_bytes_per_s = 0;
  double own_cpu = 0;  // this process (the supervisor), % of one core
};

// Every bridge's CPU and RSS, the loopback's bytes and this process's CPU,
// over `seconds`, while `during(end)` runs until monotonic_ns() `end`.
WindowFigures measure_window(const std::vector<std::unique_ptr<BridgeProcess>>& bridges,
                             double seconds, const std::function<void(std::int64_t)>& during) {
  WindowFigures w;
  std::vector<ProcessSample> before;
  for (const auto& b : bridges) before.push_back(sample_process(b->pid(), false));
  const ProcessSample own_before = sample_process(getpid(), false);
  const auto lo_before = loopback_bytes();
  const auto start = monotonic_ns();
  during(start + static_cast<std::int64_t>(seconds * 1e9));
  const auto lo_after = loopback_bytes();
  const ProcessSample own_after = sample_process(getpid(), false);
  const double wall = static_cast<double>(monotonic_ns() - start) / 1e9;
  for (const auto& b : bridges) {
    if (auto ended = b->ended()) throw std::runtime_error("a bridge ended: " + *ended);
  }
  const auto racks = static_cast<double>(bridges.size());
  const auto cpu_of = [&](const ProcessSample& from, const ProcessSample& to) {
    // Each over its own interval: the bridges are sampled one after another.
    const double interval = static_cast<double>(to.at - from.at) / 1e9;
    return core_percent(to.ticks - from.ticks, interval);
  };
  for (std::size_t i = 0; i < bridges.size(); ++i) {
    const ProcessSample after = sample_process(bridges[i]->pid(), false);
    const double cpu = cpu_of(before[i], after);
    w.cpu_mean += cpu / racks;
    w.cpu_max = std::max(w.cpu_max, cpu);
    w.cpu_all += cpu;
    const auto rss = static_cast<double>(after.rss_kb);
    w.rss_mean_kb += rss / racks;
    w.rss_max_kb = std::max(w.rss_max_kb, rss);
  }
  w.own_cpu = cpu_of(own_before, own_after);
  w.cpu_all += w.own_cpu;
  w.lo_bytes_per_s = static_cast<double>(lo_after - lo_before) / wall;
  return w;
}

// The supervisor's commands over a window, one way of reaching the bridges.
struct CommandFigures {
  WindowFigures window;
  std::uint64_t written = 0, failed = 0;
  double matched_s = -1;  // until every writer had matched its bridge(s)
  // Pumps commanded in the window, and how many of them PumpState showed
  // commanded by the supervisor by the end of the window and 2 s more.
  std::size_t pumps_commanded = 0, pumps_seen_applied = 0;
};

using PumpKey = std::tuple<std::string, unsigned>;
constexpr const char* kIssuer = "fleet supervisor";

struct FleetFigures {
  int racks = 0;
  double seen_s = -1, online_s = -1;
  WindowFigures state;
  double dnbctl_s = 0;
  std::size_t dnbctl_racks = 0;
  int dnbctl_status = 0;
  std::string stops;  // how the bridges ended, if not all with exit 0
  CommandFigures partitioned, everywhere;
};

// Commands at o.command_rate per second in all for o.window_seconds, round
// robin over the racks (rack 1 pump 1, rack 2 pump 1, ..., rack 1 pump 2,
// ...), each toggling its pump: with a writer per rack in its rack's
// partition, or (`everywhere`) one writer in every rack's partition. The
// window opens 2 s after the writers matched, so that the bridges' discovery
// of them is not in it. `wait_take(until)` waits for PumpState samples until
// `until` and takes them; `applied` is what they showed commanded by the
// supervisor (cleared here).
CommandFigures command_window(const Options& o, const dds::Participant& participant, int racks,
                              bool everywhere,
                              const std::vector<std::unique_ptr<BridgeProcess>>& bridges,
                              const std::function<void(std::int64_t)>& wait_take,
                              std::set<PumpKey>& applied) {
  CommandFigures c;
  dds::Topic<dnbridge_PumpCommand> topic(participant);
  std::vector<std::unique_ptr<dds::Writer<dnbridge_PumpCommand>>> writers;
  const auto writer_in = [&](const std::string& partition) {
    writers.push_back(std::make_unique<dds::Writer<dnbridge_PumpCommand>>(
        participant, topic,
        dds::command_writer_qos(std::vector{partition}, 10, std::chrono::seconds(2))));
  };
  if (everywhere) {
    writer_in(dds::rack_partition("*"));
  } else {
    for (int k = 1; k <= racks; ++k) writer_in(dds::rack_partition(fmt::format("fleet-{}", k)));
  }
  // Every bridge matched: each rack's writer its bridge, the one writer all.
  const auto start = monotonic_ns();
  const auto matched = [&] {
    for (const auto& w : writers) {
      const auto want = everywhere ? static_cast<std::uint32_t>(racks) : 1u;
      if (w->matched_subscriptions().value_or(0) < want) return false;
    }
    return true;
  };
  while (!matched() && monotonic_ns() - start < 30'000'000'000) {
    wait_take(monotonic_ns() + 100'000'000);
  }
  if (!matched())
    throw std::runtime_error("the command writers did not match every bridge in 30 s");
  c.matched_s = static_cast<double>(monotonic_ns() - start) / 1e9;
  for (const auto settled = monotonic_ns() + 2'000'000'000; monotonic_ns() < settled;) {
    wait_take(settled);
  }
  applied.clear();

  std::vector<std::string> rack_names;
  for (int k = 1; k <= racks; ++k) rack_names.push_back(fmt::format("fleet-{}", k));
  std::vector<bool> on(static_cast<std::size_t>(racks) * kNodesPerRack, false);
  std::set<PumpKey> commanded;
  const auto period = static_cast<std::int64_t>(1e9 / o.command_rate);
  c.window = measure_window(bridges, o.window_seconds, [&](std::int64_t end) {
    std::size_t i = 0;
    for (auto next = monotonic_ns(); next < end; next += period) {
      while (monotonic_ns() < next) wait_take(next);
      const std::size_t rack = i % static_cast<std::size_t>(racks);
      const auto mac =
          static_cast<std::uint8_t>(1 + (i / static_cast<std::size_t>(racks)) % kNodesPerRack);
      const std::size_t pump = rack * kNodesPerRack + (mac - 1);
      on[pump] = !on[pump];
      dds::Owned<dnbridge_PumpCommand> cmd;
      dds::set_string(cmd->rack, rack_names[rack]);
      dds::set_string(cmd->port, "A");
      cmd->mac = mac;
      cmd->pump_on = on[pump];
      dds::set_string(cmd->issuer, kIssuer);
      const auto& w = everywhere ? *writers.front() : *writers[rack];
      if (w.write(*cmd).ok()) {
        ++c.written;
        commanded.insert({rack_names[rack], mac});
      } else {
        ++c.failed;
      }
      ++i;
    }
  });
  for (const auto grace = monotonic_ns() + 2'000'000'000; monotonic_ns() < grace;) wait_take(grace);
  c.pumps_commanded = commanded.size();
  for (const auto& k : commanded) c.pumps_seen_applied += applied.count(k);
  return c;
}

FleetFigures run_fleet(const Options& o, int racks, const std::string& default_text,
                       const std::filesystem::path& dir) {
  FleetFigures f;
  f.racks = racks;
  const int domain = o.domain >= 0 ? o.domain : 100 + static_cast<int>(getpid() % 100);
  const std::string tag = fmt::format("dnbridge-fleet-bench-{}-{}", getpid(), racks);
  // The bridges, the supervisor and dnbctl: each a participant with an
  // index of its own on this host.
  setenv("CYCLONEDDS_URI", dds::loopback_config(tag, racks + 10).c_str(), 1);

  std::vector<std::unique_ptr<BridgeProcess>> bridges;
  for (int k = 1; k <= racks; ++k) {
    const std::string rack = fmt::format("fleet-{}", k);
    bridges.push_back(std::make_unique<BridgeProcess>(
        o.dnbridge, rack_config(default_text, rack, domain, o.poll_ms), dir, rack, -1));
  }

  const auto start = monotonic_ns();
  dds::Participant participant(static_cast<dds_domainid_t>(domain),
                               dds::Participant::ClientName{"fleet supervisor"});
  dds::Topic<dnbridge_PumpState> topic(participant);
  dds::Reader<dnbridge_PumpState> reader(participant, topic, dds::state_reader_qos());
  dds::ReadCondition data(reader, DDS_ANY_STATE);
  dds::WaitSet waitset(participant);
  waitset.attach(data, 1);
  std::set<PumpKey> seen, online, applied;
  const std::size_t all = static_cast<std::size_t>(racks) * kNodesPerRack;
  const auto take = [&] {
    auto samples = reader.take();
    if (!samples) return;
    for (const auto& s : *samples) {
      if (!s.valid_data()) continue;
      PumpKey key{std::string(dds::view(s->rack)), s->mac};
      seen.insert(key);
      if (!s->outputs_idle && dds::view(s->commanded_by) == kIssuer) applied.insert(key);
      if (s->online) {
        online.insert(key);
      } else {
        online.erase(key);
      }
    }
  };
  const auto give_up = start + static_cast<std::int64_t>(o.online_timeout_seconds * 1e9);
  while (online.size() < all && monotonic_ns() < give_up) {
    (void)waitset.wait(milliseconds(100));
    take();
    const auto now = monotonic_ns();
    if (f.seen_s < 0 && seen.size() == all) f.seen_s = static_cast<double>(now - start) / 1e9;
    if (online.size() == all) f.online_s = static_cast<double>(now - start) / 1e9;
  }
  for (auto& b : bridges) {
    if (auto ended = b->ended()) throw std::runtime_error("a bridge ended: " + *ended);
  }

  if (f.online_s >= 0) {
    // The window: the supervisor only reads.
    f.state = measure_window(bridges, o.window_seconds, [&](std::int64_t end) {
      while (monotonic_ns() < end) {
        (void)waitset.wait(milliseconds(100));
        take();
      }
    });

    // dnbctl racks, as an operator runs it.
    const auto t = monotonic_ns();
    const std::string out = run_capture(
        {o.dnbctl, "--domain", std::to_string(domain), "racks", "--json"}, &f.dnbctl_status);
    f.dnbctl_s = static_cast<double>(monotonic_ns() - t) / 1e9;
    for (auto at = out.find("\"bridge_hosts\""); at != std::string::npos;
         at = out.find("\"bridge_hosts\"", at + 1)) {
      ++f.dnbctl_racks;
    }

    const auto settle = [&] {
      // The pumps go idle when the writers go: not in the next window.
      const auto end = monotonic_ns() + 3'000'000'000;
      while (monotonic_ns() < end) {
        (void)waitset.wait(milliseconds(100));
        take();
      }
    };
    const auto wait_take = [&](std::int64_t until) {
      (void)waitset.wait(
          std::chrono::nanoseconds(std::max<std::int64_t>(0, until - monotonic_ns())));
      take();
    };
    f.partitioned = command_window(o, participant, racks, false, bridges, wait_take, applied);
    settle();
    f.everywhere = command_window(o, participant, racks, true, bridges, wait_take, applied);
  }

  // All asked to stop at once (each then idles and releases its nodes).
  for (auto& b : bridges) {
    if (b->pid() > 0) (void)kill(b->pid(), SIGTERM);
  }
  for (auto& b : bridges) {
    const std::string how = b->stop(20000);
    if (how != "exit 0") f.stops += (f.stops.empty() ? "" : "; ") + how;
  }
  return f;
}

int run(const Options& o) {
  print_run_header("dnbridge fleet benchmark");
  fmt::print(
      "each rack: {} simulated CDN127s on one port, polled every {} ms, publish policy as shipped\n"
      "(a PumpState per pump at least once a second); its bridge a dnbridge-sim process\n\n",
      kNodesPerRack, o.poll_ms);
  const std::string default_text = default_config_text(o.dnbridge);
  const auto dir =
      std::filesystem::temp_directory_path() / fmt::format("dnbridge-fleet-bench-{}", getpid());
  std::filesystem::create_directories(dir);
  struct RemoveDir {
    std::filesystem::path dir;
    ~RemoveDir() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  } remove_dir{dir};
  std::vector<FleetFigures> all;
  for (const int n : o.racks) {
    fmt::print("{} rack(s), {} pumps ...\n", n, n * static_cast<int>(kNodesPerRack));
    std::fflush(stdout);
    const FleetFigures f = run_fleet(o, n, default_text, dir);
    if (f.online_s < 0) {
      fmt::print("    not every pump online within {:.0f} s (seen {})\n", o.online_timeout_seconds,
                 f.seen_s < 0 ? "not all" : fmt::format("all after {:.2f} s", f.seen_s));
    } else {
      fmt::print(
          "    supervisor: every PumpState instance seen after {:.2f} s, every one online after "
          "{:.2f} s\n"
          "    per bridge over {:.0f} s: CPU mean {:.2f} % max {:.2f} % of one core (simulated "
          "devices included); RSS mean {:.0f} kB max {:.0f} kB\n"
          "    loopback: {:.0f} kB/s in all, {:.1f} kB/s per rack\n"
          "    dnbctl racks --json: {:.2f} s, {} rack(s) found (exit {})\n",
          f.seen_s, f.online_s, o.window_seconds, f.state.cpu_mean, f.state.cpu_max,
          f.state.rss_mean_kb, f.state.rss_max_kb, f.state.lo_bytes_per_s / 1e3,
          f.state.lo_bytes_per_s / 1e3 / f.racks, f.dnbctl_s, f.dnbctl_racks, f.dnbctl_status);
      for (const auto& [c, how] :
           {std::pair{&f.partitioned, "a writer per rack, its partition"},
            std::pair{&f.everywhere, "one writer, every rack's partition"}}) {
        fmt::print(
            "    {} commands/s ({}; matched in {:.2f} s): {} written, {} failed, {} of the {} "
            "pumps "
            "commanded seen applied; per bridge CPU "
            "mean {:.2f} % max {:.2f} %; loopback {:.0f} kB/s; supervisor CPU {:.1f} %; bridges "
            "and supervisor {:.0f} % in all\n",
            o.command_rate, how, c->matched_s, c->written, c->failed, c->pumps_seen_applied,
            c->pumps_commanded, c->window.cpu_mean, c->window.cpu_max,
            c->window.lo_bytes_per_s / 1e3, c->window.own_cpu, c->window.cpu_all);
      }
    }
    if (!f.stops.empty()) fmt::print("    bridges that did not stop with exit 0: {}\n", f.stops);
    std::fflush(stdout);
    all.push_back(f);
  }
  fmt::print(
      "\nsummary\n  racks  pumps  all seen  all online  CPU/bridge mean (max)  RSS/bridge mean  "
      "lo kB/s per rack  dnbctl racks\n");
  for (const auto& f : all) {
    fmt::print(
        "  {:5}  {:5}  {:7.2f} s  {:9.2f} s  {:8.2f} % ({:.2f} %)  {:10.0f} kB  {:16.1f}  "
        "{:.2f} s ({} found)\n",
        f.racks, f.racks * static_cast<int>(kNodesPerRack), f.seen_s, f.online_s, f.state.cpu_mean,
        f.state.cpu_max, f.state.rss_mean_kb, f.state.lo_bytes_per_s / 1e3 / f.racks, f.dnbctl_s,
        f.dnbctl_racks);
  }
  fmt::print(
      "\ncommands, {}/s in all: per bridge CPU mean (max), loopback, supervisor CPU, CPU of the\n"
      "bridges and the supervisor together (2 CPUs: 200 %)\n"
      "  racks  a writer per rack, its partition              one writer, every rack's "
      "partition\n",
      o.command_rate);
  for (const auto& f : all) {
    if (f.online_s < 0) continue;
    fmt::print("  {:5}", f.racks);
    for (const auto* c : {&f.partitioned, &f.everywhere}) {
      fmt::print("  {:5.2f} % ({:5.2f} %) {:6.0f} kB/s {:5.1f} % {:4.0f} %", c->window.cpu_mean,
                 c->window.cpu_max, c->window.lo_bytes_per_s / 1e3, c->window.own_cpu,
                 c->window.cpu_all);
    }
    fmt::print("\n");
  }
  fmt::print("load average at end: {}\n", load_average());
  return 0;
}

}  // namespace
}  // namespace dnbridge::bench

int main(int argc, char** argv) {
  using namespace dnbridge::bench;
  Options o;
  CLI::App app{"dnbridge-fleet-bench: many racks' bridges on one DDS domain"};
  app.add_option("--racks", o.racks, "fleet sizes, one run each")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--poll-ms", o.poll_ms, "poll period of every node")->capture_default_str();
  app.add_option("--window-seconds", o.window_seconds, "CPU, RSS and traffic window")
      ->capture_default_str();
  app.add_option("--command-rate", o.command_rate,
                 "the supervisor's commands per second, in all, in the command windows")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--online-timeout-seconds", o.online_timeout_seconds,
                 "how long every pump may take to be online")
      ->capture_default_str();
  app.add_option("--domain", o.domain, "DDS domain (default: from the process id)");
  app.add_option("--dnbridge", o.dnbridge, "the bridge executable")->capture_default_str();
  app.add_option("--dnbctl", o.dnbctl, "dnbctl")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dnbridge-fleet-bench: %s\n", e.what());
    return 1;
  }
}
