#include "adapters/daemon/reload.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace dnbridge::daemon {
namespace {

long long to_ms(Duration d) { return std::chrono::duration_cast<milliseconds>(d).count(); }

const PortConfig* port_named(const DaemonConfig& c, std::string_view name) {
  auto it = std::find_if(c.ports.begin(), c.ports.end(),
                         [&](const PortConfig& p) { return p.name == name; });
  return it == c.ports.end() ? nullptr : &*it;
}

std::string mac_list(const std::vector<devicenet::MacId>& macs) {
  std::string s;
  for (auto m : macs) s += fmt::format("{}{}", s.empty() ? "" : ", ", m.value());
  return s;
}

std::string mac_text(const std::vector<devicenet::MacId>& macs) {
  return fmt::format("{} {}", macs.size() == 1 ? "node" : "nodes", mac_list(macs));
}

// The simulated unconfigured devices in force that the file does not
// configure: a device the file now configures stays on the bus, and needs
// no restart for that.
std::vector<devicenet::MacId> still_unconfigured(const PortConfig& was, const PortConfig& is) {
  std::vector<devicenet::MacId> out;
  for (auto m : was.simulated_unconfigured) {
    const bool configured =
        std::any_of(is.nodes.begin(), is.nodes.end(),
                    [&](const NodeSettings& n) { return n.pump.node.mac == m; });
    if (!configured) out.push_back(m);
  }
  return out;
}

// A port's settings that need a restart, as "what: in force -> in the file".
void compare_port(const PortConfig& was, const PortConfig& is, std::vector<std::string>& out) {
  const auto differ = [&](const char* key, const std::string& a, const std::string& b) {
    if (a != b) {
      out.push_back(fmt::format("port {}: {} {} in force, {} in the file", was.name, key, a, b));
    }
  };
  differ("interface", was.interface, is.interface);
  differ("bitrate", std::to_string(was.bitrate), std::to_string(is.bitrate));
  differ("bus_off_recovery", std::string(to_string(was.bus_off_recovery)),
         std::string(to_string(is.bus_off_recovery)));
  differ("master_mac", std::to_string(was.master.master_mac.value()),
         std::to_string(is.master.master_mac.value()));
  const auto serial = [](const std::optional<std::uint32_t>& s) {
    return s ? fmt::format("0x{:08X}", *s) : std::string("derived from the host");
  };
  differ("master_serial_number", serial(was.master_serial_number), serial(is.master_serial_number));
  differ("master_vendor_id", std::to_string(was.master.vendor_id),
         std::to_string(is.master.vendor_id));
  differ("duplicate MAC ID window", fmt::format("{} ms", to_ms(was.master.duplicate_mac_window)),
         fmt::format("{} ms", to_ms(is.master.duplicate_mac_window)));
  differ("simulated_unconfigured", "[" + mac_list(still_unconfigured(was, is)) + "]",
         "[" + mac_list(is.simulated_unconfigured) + "]");
}

}  // namespace

std::string_view to_string(ReloadStatus status) noexcept {
  switch (status) {
    case ReloadStatus::kApplied:
      return "applied";
    case ReloadStatus::kRefused:
      return "refused";
    case ReloadStatus::kBusy:
      return "busy";
    case ReloadStatus::kNoFile:
      return "no file";
    case ReloadStatus::kIncomplete:
      return "incomplete";
  }
  return "?";
}

ReloadPlan plan_reload(const DaemonConfig& in_force, const DaemonConfig& next,
                       Duration offered_deadline) {
  ReloadPlan plan;
  plan.in_force = in_force;
  auto& out = plan.needs_restart;
  const auto differ = [&](const char* key, const std::string& a, const std::string& b) {
    if (a != b) out.push_back(fmt::format("{}: {} in force, {} in the file", key, a, b));
  };
  differ("rack", in_force.rack, next.rack);
  differ("domain", std::to_string(in_force.domain_id), std::to_string(next.domain_id));
  if (in_force.security.has_value() != next.security.has_value()) {
    differ("security", in_force.security ? "on" : "off", next.security ? "on" : "off");
  } else if (in_force.security) {
    const auto& a = *in_force.security;
    const auto& b = *next.security;
    if (a.identity_ca != b.identity_ca || a.certificate != b.certificate ||
        a.private_key != b.private_key || a.permissions_ca != b.permissions_ca ||
        a.governance != b.governance || a.permissions != b.permissions ||
        a.plugin_directory != b.plugin_directory) {
      out.push_back("security: its files differ from those in force");
    }
  }
  differ("max_commander_lease_ms", std::to_string(to_ms(in_force.max_commander_lease)),
         std::to_string(to_ms(next.max_commander_lease)));
  differ("metrics listen", in_force.metrics_listen.value_or("off"),
         next.metrics_listen.value_or("off"));
  for (const auto& p : next.ports) {
    if (!port_named(in_force, p.name)) {
      out.push_back(fmt::format("port {}: not in the configuration in force (a new port)", p.name));
    }
  }
  const Duration longest_publish = offered_deadline / 2;
  for (auto& p : plan.in_force.ports) {
    const PortConfig* n = port_named(next, p.name);
    if (!n) {
      out.push_back(fmt::format("port {}: no longer in the file; it runs until a restart", p.name));
      continue;
    }
    compare_port(p, *n, out);
    // Live: the nodes, and the master's timings (not its MAC nor its
    // duplicate MAC ID identity).
    devicenet::ScannerConfig master = n->master;
    master.master_mac = p.master.master_mac;
    master.vendor_id = p.master.vendor_id;
    master.duplicate_mac_window = p.master.duplicate_mac_window;
    p.master = master;
    p.nodes = n->nodes;
    if (still_unconfigured(p, *n) == n->simulated_unconfigured) {
      p.simulated_unconfigured = n->simulated_unconfigured;
    }
    for (auto& node : p.nodes) {
      if (node.publish.max_period <= longest_publish) continue;
      out.push_back(fmt::format(
          "port {}: node {}: publish_max_period_ms {}: the state topics were offered a deadline "
          "of {} ms at start; {} ms in force until a restart",
          p.name, node.pump.node.mac.value(), to_ms(node.publish.max_period),
          to_ms(offered_deadline), to_ms(longest_publish)));
      node.publish.max_period = longest_publish;
    }
  }
  plan.in_force.explicit_policy = next.explicit_policy;
  plan.in_force.log_level = next.log_level;
  plan.in_force.source = next.source;
  plan.in_force.warnings = next.warnings;
  return plan;
}

std::vector<std::string> describe(const std::string& port, const port::PortChange& change) {
  std::vector<std::string> lines;
  const auto& c = change.scan_list;
  const auto line = [&](const std::vector<devicenet::MacId>& macs, const char* what) {
    if (!macs.empty()) lines.push_back(fmt::format("port {}: {} {}", port, mac_text(macs), what));
  };
  line(c.added, "added");
  line(c.removed, "removed: idled, then released");
  line(c.reconfigured, "configured again: released, idle until a new command once back online");
  line(c.updated, "name or policies changed: applied in place");
  line(change.publish_changed, "publish policy changed");
  if (c.timings_changed) {
    lines.push_back(fmt::format("port {}: the port's timings changed, for every node", port));
  }
  if (change.explicit_policy_changed) {
    lines.push_back(fmt::format("port {}: the explicit policy changed", port));
  }
  return lines;
}

}  // namespace dnbridge::daemon
