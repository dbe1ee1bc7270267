// watch: live pump state, a line per PumpState sample, or a table redrawn
// in place on a terminal.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <set>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"

namespace dnbridge::dnbctl {
namespace {

// A redrawn table is refreshed at most this often.
constexpr auto kRedrawPeriod = std::chrono::milliseconds(200);

// "12:00:01.250", local time.
std::string clock_text() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  std::tm tm{};
  localtime_r(&t, &tm);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  return fmt::format("{:02}:{:02}:{:02}.{:03}", tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
}

}  // namespace

CLI::App* add_watch(CLI::App& app, WatchArgs& args) {
  auto* cmd = app.add_subcommand(
      "watch",
      "Live pump state (PumpState) of the given MACs, or of every pump: a table redrawn in place "
      "when stdout is a terminal, else (or with --lines) one line per sample; with --json one "
      "JSON document per line. Runs until Ctrl-C, --count or --duration.");
  cmd->add_option("NODE", args.nodes, "The nodes to watch, by MAC ID or name (default: all)");
  cmd->add_flag("--lines", args.lines, "One line per sample even on a terminal");
  cmd->add_option("--count", args.count, "Stop after N samples");
  cmd->add_option("--duration", args.duration_seconds, "Stop after S seconds")
      ->check(CLI::NonNegativeNumber);
  return cmd;
}

Exit run_watch(const GlobalOptions& o, const WatchArgs& args) {
  std::vector<NodeRef> refs;
  for (const auto& text : args.nodes) {
    auto ref = parse_node(text);
    if (!ref) throw CommandError(Exit::kUsage, ref.error());
    refs.push_back(*ref);
  }
  const bool table = !args.lines && !o.json && isatty(STDOUT_FILENO) == 1;
  install_interrupt_handlers();

  Client client = make_client(o);
  const auto wanted = [&](const NodeKey& k, const dnbridge_PumpState& s) {
    if (!o.matches(k.rack, k.port)) return false;
    if (refs.empty()) return true;
    return std::any_of(refs.begin(), refs.end(),
                       [&](const NodeRef& r) { return r.matches(k.mac, dds::view(s.name)); });
  };
  const auto start = std::chrono::steady_clock::now();
  const auto end = args.duration_seconds > 0
                       ? start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(args.duration_seconds))
                       : std::chrono::steady_clock::time_point::max();
  const Deadline first_deadline = deadline_after(o.timeout());
  std::uint64_t seen = 0;
  bool dirty = false;
  auto last_draw = start - kRedrawPeriod;

  const auto redraw = [&] {
    std::vector<const dnbridge_PumpState*> rows;
    for (const auto& [k, p] : client.pumps()) {
      if (wanted(k, *p.data) && p.alive)
        rows.push_back(p.data.get());  // a gone bridge's pumps drop out
    }
    // Home, clear screen, then the table.
    print(fmt::format("\x1b[H\x1b[2Jdnbctl watch: DDS domain {}, {} (Ctrl-C to stop)\n\n{}",
                      o.domain, clock_text(), pumps_table(rows)));
    dirty = false;
    last_draw = std::chrono::steady_clock::now();
  };

  while (!interrupted()) {
    client.refresh([&](const NodeKey& k, const Known<dnbridge_PumpState>& p) {
      if (!wanted(k, *p.data) || (args.count != 0 && seen >= args.count)) return;
      if (!p.alive) {
        // The bridge left: no new sample follows; its last one is cached.
        if (table) {
          dirty = true;
        } else if (!o.json) {
          print(fmt::format("{} {} {}: bridge gone\n", clock_text(),
                            node_name(k.rack, k.port, k.mac), dds::view(p.data->name)));
        }
        return;
      }
      ++seen;
      if (table) {
        dirty = true;
      } else if (o.json) {
        JsonWriter out(false);
        pump_json(out, *p.data);
        print(out.str() + "\n");
      } else {
        print(pump_line(*p.data, clock_text()) + "\n");
      }
    });
    const auto now = std::chrono::steady_clock::now();
    if (table && dirty && now - last_draw >= kRedrawPeriod) redraw();
    if (args.count != 0 && seen >= args.count) break;
    if (now >= end) break;
    if (seen == 0 && now >= first_deadline) {
      throw CommandError(
          Exit::kNotFound,
          fmt::format("no bridge reported pump state on DDS domain {} within {:g} s{}", o.domain,
                      o.timeout_seconds, no_bridge_causes(client, o)));
    }
    // Wakes on new samples; the slice bounds how late a redraw, the end of
    // --duration or the timeout is noticed.
    client.wait(milliseconds(100));
  }
  if (table && dirty) redraw();
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
