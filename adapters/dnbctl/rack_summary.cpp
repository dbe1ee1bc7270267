#include "adapters/dnbctl/rack_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <tuple>

#include "adapters/dds/fields.hpp"

namespace dnbridge::dnbctl {

using dds::view;

namespace {

constexpr std::array<NodeClass, kNodeClasses> kClasses{
    NodeClass::kOnline,  NodeClass::kIdle,        NodeClass::kStarting, NodeClass::kAbsent,
    NodeClass::kFaulted, NodeClass::kOtherMaster, NodeClass::kStopped,  NodeClass::kUnknown};

// A port that needs no attention: its bridge is there, its master scans, and
// the controller is error-active (or does not say).
bool healthy(const PortRow& r) {
  const auto& p = *r.port;
  return r.alive && p.state == dnbridge_PORT_RUNNING &&
         (p.bus_state == dnbridge_BUS_ERROR_ACTIVE || p.bus_state == dnbridge_BUS_STATE_UNKNOWN);
}

std::string ports_text(const RackSummary& r) {
  if (r.ports.empty()) return "-";
  const auto running = std::count_if(r.ports.begin(), r.ports.end(), [](const PortRow* p) {
    return p->alive && p->port->state == dnbridge_PORT_RUNNING;
  });
  return fmt::format("{}/{} running", running, r.ports.size());
}

}  // namespace

std::string_view to_text(NodeClass c) {
  switch (c) {
    case NodeClass::kOnline:
      return "online";
    case NodeClass::kIdle:
      return "idle";
    case NodeClass::kStarting:
      return "starting";
    case NodeClass::kAbsent:
      return "absent";
    case NodeClass::kFaulted:
      return "faulted";
    case NodeClass::kOtherMaster:
      return "owned by another master";
    case NodeClass::kStopped:
      return "stopped";
    case NodeClass::kUnknown:
      return "unknown";
  }
  return "?";
}

std::string_view json_name(NodeClass c) {
  if (c == NodeClass::kOtherMaster) return "owned_by_other_master";
  return to_text(c);
}

std::string_view to_text(BridgeState s) {
  switch (s) {
    case BridgeState::kLive:
      return "live";
    case BridgeState::kSilent:
      return "no status yet";
    case BridgeState::kGone:
      return "gone";
  }
  return "?";
}

NodeClass classify(const NodeRow& r) {
  if (!r.alive) return NodeClass::kUnknown;
  switch (r.node->state) {
    case dnbridge_NODE_ONLINE:
      // PumpState (DeviceState) says whether the device applies commanded or idle outputs.
      return r.outputs_idle().value_or(false) ? NodeClass::kIdle : NodeClass::kOnline;
    case dnbridge_NODE_IDENTIFYING:
    case dnbridge_NODE_CONFIGURING:
    case dnbridge_NODE_VERIFYING:
      return NodeClass::kStarting;
    case dnbridge_NODE_ABSENT:
      return NodeClass::kAbsent;
    case dnbridge_NODE_WRONG_DEVICE:
    case dnbridge_NODE_CONFIGURATION_FAULT:
    case dnbridge_NODE_DEVICE_FAULT:
      return NodeClass::kFaulted;
    case dnbridge_NODE_OWNED_BY_OTHER_MASTER:
      return NodeClass::kOtherMaster;
    case dnbridge_NODE_STOPPED:
      return NodeClass::kStopped;
  }
  return NodeClass::kUnknown;
}

std::string class_reason(const NodeRow& r) {
  const auto& n = *r.node;
  const std::string reason(view(n.reason));
  switch (classify(r)) {
    case NodeClass::kIdle: {
      // PumpState (DeviceState) says why ("idle: no command yet", ...); an
      // older bridge does not.
      std::string_view why = r.idle_reason();
      if (why.starts_with("idle: ")) why.remove_prefix(6);
      return fmt::format("{}: idle polls, the device holds its configured idle state",
                         why.empty() ? "no commander" : why);
    }
    case NodeClass::kAbsent: {
      std::string s = reason;
      s += fmt::format(" ({} Allocate attempt{}", n.counters.allocate_attempts,
                       n.counters.allocate_attempts == 1 ? "" : "s");
      if (!view(n.last_error).empty()) s += fmt::format("; last error: {}", view(n.last_error));
      return s + ")";
    }
    case NodeClass::kUnknown:
      return fmt::format("no longer published by a bridge; last reported {}: {}", to_text(n.state),
                         reason);
    case NodeClass::kOnline:
      if (!r.commanded_by().empty()) {
        return fmt::format("{}; commanded by {}", reason, r.commanded_by());
      }
      return reason;
    default:
      return reason;
  }
}

std::vector<RackSummary> summarize_racks(
    std::span<const PortRow> ports, std::span<const NodeRow> nodes,
    const std::map<std::string, std::vector<std::string>>& participants) {
  std::map<std::string, RackSummary, std::less<>> racks;
  const auto rack = [&racks](std::string_view name) -> RackSummary& {
    auto it = racks.find(name);
    if (it == racks.end()) {
      it = racks.emplace(std::string(name), RackSummary{}).first;
      it->second.rack = std::string(name);
    }
    return it->second;
  };
  for (const auto& [name, hosts] : participants) {
    RackSummary& r = rack(name);
    r.participants = static_cast<unsigned>(hosts.size());
    r.hosts = hosts;
  }
  for (const auto& p : ports) rack(view(p.port->rack)).ports.push_back(&p);
  for (const auto& n : nodes) rack(view(n.node->rack)).nodes.push_back(&n);

  std::vector<RackSummary> out;
  for (auto& [name, r] : racks) {
    std::sort(r.ports.begin(), r.ports.end(), [](const PortRow* a, const PortRow* b) {
      return view(a->port->port) < view(b->port->port);
    });
    std::sort(r.nodes.begin(), r.nodes.end(), [](const NodeRow* a, const NodeRow* b) {
      return std::tuple(view(a->node->port), a->node->mac) <
             std::tuple(view(b->node->port), b->node->mac);
    });
    const bool published = !r.ports.empty() || !r.nodes.empty();
    const bool alive =
        std::any_of(r.ports.begin(), r.ports.end(), [](const PortRow* p) { return p->alive; }) ||
        std::any_of(r.nodes.begin(), r.nodes.end(), [](const NodeRow* n) { return n->alive; });
    r.bridge = !published                    ? BridgeState::kSilent
               : alive || r.participants > 0 ? BridgeState::kLive
                                             : BridgeState::kGone;
    for (const auto* n : r.nodes) ++r.counts[static_cast<std::size_t>(classify(*n))];
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

// A rack's line of the summary: its counts per class are table cells of
// their own, and an object in JSON.
Record rack_record(const RackSummary& r) {
  const bool silent = r.bridge == BridgeState::kSilent;
  const auto count = [silent](std::size_t n) {
    return silent ? std::string("-") : fmt::format("{}", n);
  };
  Record counts;
  counts.add("nodes", count(r.nodes.size()), "nodes", r.nodes.size());
  for (auto c : kClasses) {
    counts.add(c == NodeClass::kOtherMaster ? "other master" : std::string(to_text(c)),
               count(r.count(c)), std::string(json_name(c)), r.count(c));
  }
  std::vector<Record> ports;
  for (const auto* p : r.ports) {
    Record port = port_record(*p->port);
    port.json("bridge_alive", p->alive).json("healthy", healthy(*p));
    ports.push_back(std::move(port));
  }
  std::vector<Record> nodes;
  for (const auto* n : r.nodes) nodes.push_back(rack_node_record(*n));

  std::string bridge(to_text(r.bridge));
  if (r.participants > 1) {
    // Which hosts, so that the one with the wrong rack name can be found.
    std::string where;
    for (const auto& h : r.hosts) {
      where += fmt::format("{}{}", where.empty() ? "" : ", ", h.empty() ? "?" : h);
    }
    bridge += fmt::format(" ({} bridges!: {})", r.participants, where);
  }
  std::vector<Json> hosts;
  for (const auto& h : r.hosts) hosts.emplace_back(h);
  Record rec;
  rec.add("rack", r.rack, "rack", r.rack)
      .add("bridge", std::move(bridge),
           {{"bridge", to_text(r.bridge)},
            {"participants", r.participants},
            {"bridge_hosts", Json::values(std::move(hosts))}})
      .nest("counts", std::move(counts))
      .add("ports", ports_text(r), "ports", Json::array(std::move(ports)))
      .json("nodes", Json::array(std::move(nodes)));
  return rec;
}

}  // namespace

Record rack_node_record(const NodeRow& row) {
  const auto& n = *row.node;
  const NodeClass c = classify(row);
  Record r;
  r.text("rack", std::string(view(n.rack)))
      .add("port", std::string(view(n.port)), "port", view(n.port))
      .add("mac", fmt::format("{}", n.mac), "mac", n.mac)
      .add("name", std::string(view(n.name)), "name", view(n.name))
      .add("class", std::string(to_text(c)), "class", json_name(c))
      .add("state", std::string(to_text(n.state)), "state", to_text(n.state))
      .add("reason", class_reason(row), "reason", class_reason(row))
      .json("state_reason", view(n.reason))
      .json("last_error", view(n.last_error))
      .json("allocate_attempts", n.counters.allocate_attempts)
      .json("outputs_idle", row.outputs_idle() ? Json(*row.outputs_idle()) : Json())
      .json("commanded_by", row.pump || row.device ? Json(row.commanded_by()) : Json());
  return r;
}

std::string racks_text(std::span<const RackSummary> racks) {
  std::vector<std::string_view> columns{"rack", "bridge", "ports", "nodes"};
  for (auto c : kClasses)
    columns.push_back(c == NodeClass::kOtherMaster ? "other master" : to_text(c));
  std::vector<Record> rows;
  for (const auto& r : racks) rows.push_back(rack_record(r));
  std::string text = table(columns, rows);

  static constexpr std::string_view kPortColumns[] = {"rack", "port", "state", "bus", "reason"};
  std::vector<Record> problem_ports;
  for (const auto& r : racks) {
    for (const auto* p : r.ports) {
      if (healthy(*p)) continue;
      Record port = port_record(*p->port);
      port.text("rack", r.rack);
      if (!p->alive) port.retext("state", "bridge gone");
      problem_ports.push_back(std::move(port));
    }
  }
  if (!problem_ports.empty()) text += "\n" + table(kPortColumns, problem_ports);

  static constexpr std::string_view kNodeColumns[] = {"rack",  "port",  "mac",   "name",
                                                      "class", "state", "reason"};
  std::vector<Record> not_online;
  for (const auto& r : racks) {
    for (const auto* n : r.nodes) {
      if (classify(*n) != NodeClass::kOnline) not_online.push_back(rack_node_record(*n));
    }
  }
  text += "\n";
  text += not_online.empty() ? "every node reported is online\n" : table(kNodeColumns, not_online);
  return text;
}

void racks_json(JsonWriter& out, std::span<const RackSummary> racks) {
  std::vector<Record> items;
  for (const auto& r : racks) items.push_back(rack_record(r));
  Record doc;
  doc.json("racks", Json::array(std::move(items)));
  doc.write(out);
}

}  // namespace dnbridge::dnbctl
