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
//     found.
// Every participant is on the loopback interface with unicast discovery and
// a discovery tag of the run's own. It reports figures; it exits non-zero
// only when the run itself fails.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/loopback.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
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

struct FleetFigures {
  int racks = 0;
  double seen_s = -1, online_s = -1;
  double cpu_mean = 0, cpu_max = 0;  // % of one core, per bridge
  double rss_mean_kb = 0, rss_max_kb = 0;
  double lo_bytes_per_s = 0;
  double dnbctl_s = 0;
  std::size_t dnbctl_racks = 0;
  int dnbctl_status = 0;
  std::string stops;  // how the bridges ended, if not all with exit 0
};

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
  std::set<std::tuple<std::string, unsigned>> seen, online;
  const std::size_t all = static_cast<std::size_t>(racks) * kNodesPerRack;
  const auto take = [&] {
    auto samples = reader.take();
    if (!samples) return;
    for (const auto& s : *samples) {
      if (!s.valid_data()) continue;
      std::tuple<std::string, unsigned> key{std::string(dds::view(s->rack)), s->mac};
      seen.insert(key);
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
    // The window: every bridge's CPU and RSS, the loopback's bytes.
    std::vector<ProcessSample> before;
    for (auto& b : bridges) before.push_back(sample_process(b->pid(), false));
    const auto lo_before = loopback_bytes();
    const auto window_start = monotonic_ns();
    const auto window_end = window_start + static_cast<std::int64_t>(o.window_seconds * 1e9);
    while (monotonic_ns() < window_end) {
      (void)waitset.wait(milliseconds(100));
      take();
    }
    const auto lo_after = loopback_bytes();
    const double wall = static_cast<double>(monotonic_ns() - window_start) / 1e9;
    const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
    for (auto& b : bridges) {
      if (auto ended = b->ended()) throw std::runtime_error("a bridge ended: " + *ended);
    }
    for (std::size_t i = 0; i < bridges.size(); ++i) {
      const ProcessSample after = sample_process(bridges[i]->pid(), false);
      // Each over its own interval: the bridges are sampled one after another.
      const double seconds = static_cast<double>(after.at - before[i].at) / 1e9;
      const double cpu =
          100.0 * static_cast<double>(after.ticks - before[i].ticks) / tick / seconds;
      f.cpu_mean += cpu / static_cast<double>(racks);
      f.cpu_max = std::max(f.cpu_max, cpu);
      const auto rss = static_cast<double>(after.rss_kb);
      f.rss_mean_kb += rss / static_cast<double>(racks);
      f.rss_max_kb = std::max(f.rss_max_kb, rss);
    }
    f.lo_bytes_per_s = static_cast<double>(lo_after - lo_before) / wall;

    // dnbctl racks, as an operator runs it.
    const auto t = monotonic_ns();
    const std::string out = run_capture(
        {o.dnbctl, "--domain", std::to_string(domain), "racks", "--json"}, &f.dnbctl_status);
    f.dnbctl_s = static_cast<double>(monotonic_ns() - t) / 1e9;
    for (auto at = out.find("\"bridge_hosts\""); at != std::string::npos;
         at = out.find("\"bridge_hosts\"", at + 1)) {
      ++f.dnbctl_racks;
    }
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
          f.seen_s, f.online_s, o.window_seconds, f.cpu_mean, f.cpu_max, f.rss_mean_kb,
          f.rss_max_kb, f.lo_bytes_per_s / 1e3, f.lo_bytes_per_s / 1e3 / f.racks, f.dnbctl_s,
          f.dnbctl_racks, f.dnbctl_status);
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
        f.racks, f.racks * static_cast<int>(kNodesPerRack), f.seen_s, f.online_s, f.cpu_mean,
        f.cpu_max, f.rss_mean_kb, f.lo_bytes_per_s / 1e3 / f.racks, f.dnbctl_s, f.dnbctl_racks);
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
