#pragma once
// A configuration read again while the bridge runs (SIGHUP, systemctl
// reload, dnbctl reload): which of its settings change live, which wait for
// a restart, and the words of the report.
#include <cstdint>
#include <string>
#include <vector>

#include "adapters/daemon/config.hpp"
#include "adapters/port/port_loop.hpp"

namespace dnbridge::daemon {

// How a reload ended (the IDL's RELOAD_*).
enum class ReloadStatus : std::uint8_t {
  kApplied = 1,     // checked and applied (nothing, when nothing differed)
  kRefused = 2,     // the file has problems: nothing changed
  kBusy = 3,        // too many reloads waiting
  kNoFile = 4,      // the bridge runs its embedded default
  kIncomplete = 5,  // checked, but a port did not apply it
};
std::string_view to_string(ReloadStatus status) noexcept;

// A reload asked for: by DDS (ReloadRequest: a requester and its txid) or
// by a signal (SIGHUP: no requester, nothing to answer).
struct ReloadCall {
  std::string requester;
  std::uint32_t txid = 0;
};

struct ReloadReport {
  ReloadStatus status = ReloadStatus::kApplied;
  std::string message;
  std::string file;
  std::vector<std::string> applied;        // "port p0: node 12 added", ...
  std::vector<std::string> needs_restart;  // what differs and waits for a restart
  std::vector<std::string> problems;       // kRefused: "FILE:LINE:COLUMN: ..."
};

// What a reload of `next` over the configuration in force makes of it.
// Live: each port's nodes and the port's timings, the explicit policy, the
// log level. Everything else keeps its value in force until a restart, and
// each difference is a line of `needs_restart`: the rack's name, its DDS
// domain, security and metrics address; ports added or removed; a port's
// interface, bit rate, bus-off recovery, master MAC, master serial number,
// duplicate MAC ID vendor and window, and simulated unconfigured nodes.
// `offered_deadline`: the deadline the state topics were offered with at
// start; a node's publish_max_period_ms is kept within half of it (longer
// needs a restart, and is said so).
struct ReloadPlan {
  DaemonConfig in_force;  // after the reload
  std::vector<std::string> needs_restart;
};
ReloadPlan plan_reload(const DaemonConfig& in_force, const DaemonConfig& next,
                       Duration offered_deadline);

// What a port's change was, one line each ("port p0: node 12 added").
std::vector<std::string> describe(const std::string& port, const port::PortChange& change);

}  // namespace dnbridge::daemon
