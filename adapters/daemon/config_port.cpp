// A [[port]] table: its interface, bit rate, bus-off recovery, master and
// timings, its [[port.node]] tables (MACs and names unique on the port) and
// the simulated devices a simulated port adds.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "adapters/daemon/config_internal.hpp"

namespace dnbridge::daemon::config_detail {

using toml_config::read_integer;
using toml_config::read_name;
using toml_config::read_string;
using toml_config::type_name;

namespace {

// A SocketCAN interface name: at most IFNAMSIZ - 1 = 15 characters, no slash
// or white space (what the kernel accepts as a network device name).
bool valid_interface_name(std::string_view name) {
  if (name.empty() || name.size() > 15 || name == "." || name == "..") return false;
  return std::none_of(name.begin(), name.end(), [](char c) {
    return c == '/' || c == ':' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\0';
  });
}

struct NodeSeen {
  std::string name;
  std::uint32_t line;
};

// simulated_unconfigured = [MAC, ...]: a simulated port's devices at MACs
// its nodes do not have.
void read_simulated_unconfigured(const toml::node& n, PortConfig& port, Problems& r) {
  const toml::array* list = n.as_array();
  if (!list) {
    r.error(n.source(), fmt::format("simulated_unconfigured must be an array of MAC IDs, not {}",
                                    type_name(n.type())));
    return;
  }
  if (port.interface != kSimulatedInterface) {
    r.error(n.source(), "simulated_unconfigured is for a port whose interface is \"simulated\"");
    return;
  }
  for (const toml::node& element : *list) {
    auto mac = read_mac(element, "simulated_unconfigured", r);
    if (!mac) continue;
    const bool configured = std::any_of(port.nodes.begin(), port.nodes.end(),
                                        [&](const auto& s) { return s.pump.node.mac == *mac; });
    if (configured || *mac == port.master.master_mac) {
      r.error(element.source(), fmt::format("simulated_unconfigured: MAC {} is {}", mac->value(),
                                            configured ? "a configured node's" : "the master's"));
    } else if (std::find(port.simulated_unconfigured.begin(), port.simulated_unconfigured.end(),
                         *mac) != port.simulated_unconfigured.end()) {
      r.error(element.source(),
              fmt::format("simulated_unconfigured: MAC {} is given twice", mac->value()));
    } else {
      port.simulated_unconfigured.push_back(*mac);
    }
  }
}

void read_port_nodes(TableReader& t, const toml::table& table, PortConfig& port,
                     TableReader* defaults, ReadContext& ctx, Problems& r);

}  // namespace

PortConfig read_port(const toml::table& table, const DaemonConfig& rack, TableReader* defaults,
                     ReadContext& ctx, Problems& r) {
  TableReader t(table, "[[port]]", r);
  t.allow_only(key_names(KeyPlace::kPort),
               [](std::string_view key) { return misplaced_key(KeyPlace::kPort, false, key); });
  PortConfig port;
  port.master.master_mac = rack.master_mac;
  if (const toml::node* n = t.require("name")) {
    if (auto v = read_name(*n, "name", r)) port.name = *v;
  }
  if (const toml::node* n = t.require("interface")) {
    if (auto v = read_string(*n, "interface", r)) {
      if (*v == kSimulatedInterface || valid_interface_name(*v)) {
        port.interface = *v;
      } else {
        r.error(n->source(),
                fmt::format("interface = \"{}\" is not a CAN interface name: use \"simulated\" or "
                            "a SocketCAN interface such as \"can0\" (at most 15 characters)",
                            *v));
      }
    }
  }
  if (const toml::node* n = t.require("bitrate")) {
    if (auto v = read_integer(
            *n, "bitrate",
            {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()},
            r)) {
      if (*v == 125000 || *v == 250000 || *v == 500000) {
        port.bitrate = static_cast<std::uint32_t>(*v);
      } else {
        r.error(n->source(),
                fmt::format(
                    "bitrate = {} is not a DeviceNet bit rate: use 125000, 250000 or 500000", *v));
      }
    }
  }
  if (const toml::node* n = t.get("bus_off_recovery")) {
    if (auto v = read_string(*n, "bus_off_recovery", r)) {
      if (*v == "interface") {
        port.bus_off_recovery = BusOffRecovery::kInterface;
      } else if (*v == "restart") {
        port.bus_off_recovery = BusOffRecovery::kRestart;
      } else if (*v == "report") {
        port.bus_off_recovery = BusOffRecovery::kReport;
      } else {
        r.error(n->source(),
                fmt::format("bus_off_recovery = \"{}\" is not a policy: use \"interface\", "
                            "\"restart\" or \"report\"",
                            *v));
      }
    }
  }
  const toml::node* master_mac_node = t.get("master_mac");
  if (master_mac_node) {
    if (auto v = read_mac(*master_mac_node, "master_mac", r)) port.master.master_mac = *v;
  }
  if (const toml::node* n = t.get("master_vendor_id")) {
    if (auto v = read_key_int<std::uint16_t>(*n, KeyPlace::kPort, "master_vendor_id", r)) {
      port.master.vendor_id = *v;
    }
  }
  if (const toml::node* n = t.get("master_serial_number")) {
    if (auto v = read_key_int<std::uint32_t>(*n, KeyPlace::kPort, "master_serial_number", r)) {
      port.master_serial_number = *v;
    }
  }

  auto timing = [&](std::string_view key, Duration& out) {
    if (const toml::node* n = t.get(key)) {
      if (auto v = read_key_ms(*n, KeyPlace::kPort, key, r)) out = *v;
    }
  };
  devicenet::ScannerConfig& tm = port.master;
  timing("allocate_retry_min_ms", tm.allocate_retry_min);
  timing("allocate_retry_max_ms", tm.allocate_retry_max);
  timing("fault_recheck_ms", tm.fault_recheck);
  timing("poll_response_timeout_ms", tm.poll_response_timeout);
  timing("explicit_response_timeout_ms", tm.explicit_messaging.response_timeout);
  timing("scan_response_timeout_ms", tm.scan_response_timeout);
  if (const toml::node* n = t.get("poll_batch_ms")) {
    if (auto v = read_key_ms(*n, KeyPlace::kPort, "poll_batch_ms", r)) tm.poll_batch_window = *v;
  }
  if (const toml::node* n = t.get("max_consecutive_errors")) {
    if (auto v = read_key_int<unsigned>(*n, KeyPlace::kPort, "max_consecutive_errors", r)) {
      tm.max_consecutive_errors = *v;
    }
  }
  if (tm.allocate_retry_max < tm.allocate_retry_min) {
    const toml::node* n = t.get("allocate_retry_max_ms");
    if (!n) n = t.get("allocate_retry_min_ms");
    r.error(n ? n->source() : table.source(),
            "allocate_retry_max_ms is shorter than allocate_retry_min_ms");
  }

  if (const toml::node* n = t.get("command_refresh_ms")) {
    port.command_refresh = read_command_refresh(*n, r);
  }

  read_port_nodes(t, table, port, defaults, ctx, r);
  if (const toml::node* n = t.get("simulated_unconfigured")) {
    read_simulated_unconfigured(*n, port, r);
  }
  return port;
}

namespace {

// The port's [[port.node]] tables.
void read_port_nodes(TableReader& t, const toml::table& table, PortConfig& port,
                     TableReader* defaults, ReadContext& ctx, Problems& r) {
  const toml::node* master_mac_node = t.get("master_mac");
  const toml::node* nodes = t.get("node");
  const toml::array* list = nodes ? nodes->as_array() : nullptr;
  if (nodes && (!list || !list->is_array_of_tables())) {
    r.error(nodes->source(), fmt::format("node must be an array of tables ([[port.node]]), not {}",
                                         type_name(nodes->type())));
    return;
  }
  if (!list || list->empty()) {
    r.warning(table.source(), fmt::format("port \"{}\" has no [[port.node]]: its master scans "
                                          "nothing",
                                          port.name));
    return;
  }

  std::map<std::uint8_t, NodeSeen> macs;
  std::map<std::string, std::uint32_t> names;
  for (const toml::node& element : *list) {
    TableReader nt(*element.as_table(), "[[port.node]]", r);
    nt.allow_only(key_names(KeyPlace::kNode),
                  [](std::string_view key) { return misplaced_key(KeyPlace::kNode, false, key); });
    NodeSettings s;
    bool ok = true;
    const toml::node* mac_node = nt.require("mac");
    const toml::node* name_node = nt.require("name");
    std::optional<MacId> mac = mac_node ? read_mac(*mac_node, "mac", r) : std::nullopt;
    std::optional<std::string> name = name_node ? read_name(*name_node, "name", r) : std::nullopt;
    if (mac) {
      s.pump.node.mac = *mac;
      if (*mac == port.master.master_mac) {
        r.error(mac_node->source(),
                fmt::format(
                    "mac = {} is the master's own MAC on port \"{}\"{}", mac->value(), port.name,
                    master_mac_node
                        ? fmt::format(" (master_mac, line {})", line_of(master_mac_node->source()))
                        : std::string(" (the rack's master_mac)")));
        ok = false;
      }
      const std::uint32_t line = line_of(mac_node->source());
      auto [it, added] = macs.try_emplace(mac->value(), NodeSeen{name.value_or(""), line});
      if (!added) {
        r.error(mac_node->source(),
                fmt::format("mac = {} is already used on port \"{}\" by node \"{}\" (line {})",
                            mac->value(), port.name, it->second.name, it->second.line));
        ok = false;
      }
    } else {
      ok = false;
    }
    if (const toml::node* serial = nt.get("serial")) {
      if (auto v = read_key_int<std::uint32_t>(*serial, KeyPlace::kNode, "serial", r)) {
        s.pump.node.serial_number = *v;
      } else {
        ok = false;
      }
    }
    if (name) {
      s.pump.node.name = *name;
      const std::uint32_t line = line_of(name_node->source());
      auto [it, added] = names.try_emplace(*name, line);
      if (!added) {
        r.error(name_node->source(),
                fmt::format("name \"{}\" is already used on port \"{}\" (line {})", *name,
                            port.name, it->second));
        ok = false;
      }
    } else {
      ok = false;
    }
    read_node_settings(Layers{&nt, defaults}, s, r);
    // The port's command refresh before [defaults]', after the node's own.
    if (port.command_refresh && !nt.get("command_refresh_ms")) {
      s.pump.command_refresh = *port.command_refresh;
    }
    if (s.pump.command_refresh > Duration::zero() &&
        s.pump.no_commander == NoCommanderPolicy::kHoldLastOutputs && name_node) {
      r.warning(name_node->source(),
                fmt::format("node \"{}\" has a command refresh and no_commander = \"hold\": "
                            "the outputs of a commander that falls silent stay as it left them",
                            s.pump.node.name));
    }
    refuse_other_profiles_keys(nt, s.is_eds() ? kEdsNodes : kCdn127Nodes, r);
    if (s.is_eds()) read_eds_node(Layers{&nt, defaults}, ctx, s, r);
    if (ok) port.nodes.push_back(std::move(s));
  }
}

}  // namespace

}  // namespace dnbridge::daemon::config_detail
