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
      // PumpState says whether the device applies commanded or idle outputs.
      return r.pump && r.pump->outputs_idle ? NodeClass::kIdle : NodeClass::kOnline;
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
      // PumpState says why ("idle: no command yet", ...); an older bridge
      // does not.
      std::string_view why = r.pump ? view(r.pump->idle_reason) : std::string_view{};
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
      if (r.pump && !view(r.pump->commanded_by).empty()) {
        return fmt::format("{}; commanded by {}", reason, view(r.pump->commanded_by));
      }
      return reason;
    default:
      return reason;
  }
}

std::vector<RackSummary> summarize_racks(std::span<const PortRow> ports,
                                         std::span<const NodeRow> nodes,
                                         const std::map<std::string, unsigned>& participants) {
  std::map<std::string, RackSummary, std::less<>> racks;
  const auto rack = [&racks](std::string_view name) -> RackSummary& {
    auto it = racks.find(name);
    if (it == racks.end()) {
      it = racks.emplace(std::string(name), RackSummary{}).first;
      it->second.rack = std::string(name);
    }
    return it->second;
  };
  for (const auto& [name, count] : participants) rack(name).participants = count;
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

std::string racks_text(std::span<const RackSummary> racks) {
  std::vector<std::string> headers{"RACK", "BRIDGE", "PORTS", "NODES"};
  for (auto c : kClasses) {
    std::string h(c == NodeClass::kOtherMaster ? "other master" : to_text(c));
    std::transform(h.begin(), h.end(), h.begin(),
                   [](unsigned char ch) { return std::toupper(ch); });
    headers.push_back(std::move(h));
  }
  Table summary(std::move(headers));
  for (const auto& r : racks) {
    std::string bridge(to_text(r.bridge));
    if (r.participants > 1) bridge += fmt::format(" ({} bridges!)", r.participants);
    std::vector<std::string> row{r.rack, bridge, ports_text(r)};
    const bool silent = r.bridge == BridgeState::kSilent;
    row.push_back(silent ? "-" : fmt::format("{}", r.nodes.size()));
    for (auto c : kClasses) row.push_back(silent ? "-" : fmt::format("{}", r.count(c)));
    summary.add(std::move(row));
  }
  std::string text = summary.render();

  Table ports({"RACK", "PORT", "STATE", "BUS", "REASON"});
  bool port_problems = false;
  for (const auto& r : racks) {
    for (const auto* p : r.ports) {
      if (healthy(*p)) continue;
      port_problems = true;
      ports.add({r.rack, std::string(view(p->port->port)),
                 p->alive ? std::string(to_text(p->port->state)) : "bridge gone",
                 std::string(to_text(p->port->bus_state)), std::string(view(p->port->reason))});
    }
  }
  if (port_problems) text += "\n" + ports.render();

  Table nodes({"RACK", "PORT", "MAC", "NAME", "CLASS", "STATE", "REASON"});
  bool not_online = false;
  for (const auto& r : racks) {
    for (const auto* n : r.nodes) {
      const NodeClass c = classify(*n);
      if (c == NodeClass::kOnline) continue;
      not_online = true;
      nodes.add({r.rack, std::string(view(n->node->port)), fmt::format("{}", n->node->mac),
                 std::string(view(n->node->name)), std::string(to_text(c)),
                 std::string(to_text(n->node->state)), class_reason(*n)});
    }
  }
  text += "\n";
  text += not_online ? nodes.render() : "every node reported is online\n";
  return text;
}

void racks_json(JsonWriter& out, std::span<const RackSummary> racks) {
  out.begin_object().key("racks").begin_array();
  for (const auto& r : racks) {
    out.begin_object()
        .field("rack", r.rack)
        .field("bridge", to_text(r.bridge))
        .field("participants", r.participants);
    out.key("counts").begin_object().field("nodes", r.nodes.size());
    for (auto c : kClasses) out.field(json_name(c), r.count(c));
    out.end_object();
    out.key("ports").begin_array();
    for (const auto* p : r.ports) {
      out.begin_object();
      port_json_members(out, *p->port);
      out.field("bridge_alive", p->alive).field("healthy", healthy(*p)).end_object();
    }
    out.end_array();
    out.key("nodes").begin_array();
    for (const auto* n : r.nodes) {
      const auto& s = *n->node;
      out.begin_object()
          .field("port", view(s.port))
          .field("mac", unsigned{s.mac})
          .field("name", view(s.name))
          .field("class", json_name(classify(*n)))
          .field("state", to_text(s.state))
          .field("reason", class_reason(*n))
          .field("state_reason", view(s.reason))
          .field("last_error", view(s.last_error))
          .field("allocate_attempts", s.counters.allocate_attempts);
      if (n->pump) {
        out.field("outputs_idle", static_cast<bool>(n->pump->outputs_idle))
            .field("commanded_by", view(n->pump->commanded_by));
      } else {
        out.key("outputs_idle").null().key("commanded_by").null();
      }
      out.end_object();
    }
    out.end_array().end_object();
  }
  out.end_array().end_object();
}

}  // namespace dnbridge::dnbctl
