// list: a port's PortStatus as every command shows it, the ports and nodes
// as tables, and the racks as JSON.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <map>
#include <tuple>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/states.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/format_internal.hpp"

namespace dnbridge::dnbctl {

using dds::view;
using format_detail::yes_no;

namespace {

// The order of the keys (rack, port, mac), for sorted output.
using RowKey = std::tuple<std::string_view, std::string_view, unsigned>;

// "8/8 online", and the MACs heard that the configuration does not have:
// "7/8 online; unconfigured heard: 17, 23".
std::string nodes_text(const dnbridge_PortStatus& p) {
  std::string s = fmt::format("{}/{} online", p.nodes_online, p.nodes_configured);
  const auto macs = view(p.unconfigured_macs);
  if (!macs.empty()) s += fmt::format("; unconfigured heard: {}", fmt::join(macs, ", "));
  return s;
}

// "lease at most 10000 ms", with the commanders and endpoints the bridge
// does not match: "lease at most 10000 ms; 1 commander refused, 2 endpoints
// unmatched (the bridge's log says who)".
std::string commanders_text(const dnbridge_PortStatus& p) {
  std::string s = fmt::format("lease at most {} ms", p.max_commander_lease_ms);
  if (p.commanders_refused == 0 && p.endpoints_unmatched == 0) return s;
  s += fmt::format("; {} commander{} refused, {} endpoint{} unmatched (the bridge's log says who)",
                   p.commanders_refused, p.commanders_refused == 1 ? "" : "s",
                   p.endpoints_unmatched, p.endpoints_unmatched == 1 ? "" : "s");
  return s;
}

Json unconfigured_json(const dnbridge_PortStatus& p) {
  std::vector<Json> macs;
  for (const auto mac : view(p.unconfigured_macs)) macs.emplace_back(static_cast<unsigned>(mac));
  return Json::values(std::move(macs));
}

}  // namespace

Record port_record(const dnbridge_PortStatus& p) {
  Record r;
  r.add("port", std::string(view(p.port)), "port", view(p.port))
      .add("state", std::string(to_text(p.state)), "state", to_text(p.state))
      .add("reason", std::string(view(p.reason)), "reason", view(p.reason))
      .add("interface",
           fmt::format("{} {}k master {}", view(p.can_interface), p.bitrate / 1000, p.master_mac),
           {{"can_interface", view(p.can_interface)},
            {"bitrate", p.bitrate},
            {"master_mac", p.master_mac}})
      .add("bus", std::string(to_text(p.bus_state)), "bus_state", to_text(p.bus_state))
      .json("tx_error_counter", p.tx_error_counter)
      .json("rx_error_counter", p.rx_error_counter)
      .add("frames/s", fmt::format("{:.0f}", p.frames_per_second), "frames_per_second",
           Decimal{p.frames_per_second, 1})
      .add("load", fmt::format("{:.1f}%", p.bus_load_percent), "bus_load_percent",
           Decimal{p.bus_load_percent, 1})
      .json("scan_cycle_ms", Decimal{p.scan_cycle_ms, 1})
      .add("nodes", nodes_text(p),
           {{"nodes_online", p.nodes_online},
            {"nodes_configured", p.nodes_configured},
            {"unconfigured_macs", unconfigured_json(p)}})
      .json("explicit_outstanding", p.explicit_outstanding)
      .json("explicit_retained", p.explicit_retained)
      .json("explicit_refused_for_limits", p.explicit_refused_for_limits)
      .json("replies_undelivered", p.replies_undelivered)
      .json("loop_longest_pass_ms", Decimal{p.loop_longest_pass_ms, 2})
      .add("commanders", commanders_text(p),
           {{"max_commander_lease_ms", p.max_commander_lease_ms},
            {"commanders_refused", p.commanders_refused},
            {"endpoints_unmatched", p.endpoints_unmatched}});
  return r;
}

void port_json_members(JsonWriter& out, const dnbridge_PortStatus& p) {
  port_record(p).write_members(out);
}

std::string ports_table(std::span<const PortRow> ports) {
  static constexpr std::string_view kColumns[] = {
      "rack", "port", "bridge", "state", "bus", "load", "frames/s", "nodes", "interface", "reason"};
  std::vector<Record> rows;
  for (const auto& r : ports) {
    rows.push_back(port_record(*r.port)
                       .text("rack", std::string(view(r.port->rack)))
                       .text("bridge", r.alive ? "live" : "gone"));
  }
  return table(kColumns, rows);
}

std::optional<bool> NodeRow::online() const {
  if (pump) return pump->online;
  if (device) return device->online;
  return std::nullopt;
}

std::optional<bool> NodeRow::outputs_idle() const {
  if (pump) return pump->outputs_idle;
  if (device) return device->outputs_idle;
  return std::nullopt;
}

std::string_view NodeRow::idle_reason() const {
  return pump ? view(pump->idle_reason) : device ? view(device->idle_reason) : std::string_view{};
}

std::string_view NodeRow::commanded_by() const {
  return pump ? view(pump->commanded_by) : device ? view(device->commanded_by) : std::string_view{};
}

bool node_online(const NodeRow& r) {
  return r.alive && r.online().value_or(r.node->state == dnbridge_NODE_ONLINE);
}

namespace {

// A node as `list` shows it.
Record node_row_record(const NodeRow& r) {
  const auto& n = *r.node;
  Record rec;
  rec.text("rack", std::string(view(n.rack)))
      .text("port", std::string(view(n.port)))
      .add("mac", fmt::format("{}", n.mac), "mac", n.mac)
      .add("name", std::string(view(n.name)), "name", view(n.name))
      .add("state", std::string(to_text(n.state)), "state", to_text(n.state))
      .add("reason",
           r.alive ? std::string(view(n.reason)) : "bridge gone: " + std::string(view(n.reason)),
           "reason", view(n.reason))
      .add("product", std::string(view(n.product_name)), "product", view(n.product_name))
      .add("online", yes_no(node_online(r)), "online", node_online(r));
  return rec;
}

}  // namespace

std::string nodes_table(std::span<const NodeRow> nodes) {
  static constexpr std::string_view kColumns[] = {"rack",  "port",   "mac",     "name",
                                                  "state", "online", "product", "reason"};
  std::vector<Record> rows;
  for (const auto& r : nodes) rows.push_back(node_row_record(r));
  return table(kColumns, rows);
}

void list_json(JsonWriter& out, std::span<const PortRow> ports, std::span<const NodeRow> nodes) {
  // rack -> port -> (status, nodes), sorted by name.
  struct PortEntry {
    const PortRow* row = nullptr;
    std::vector<const NodeRow*> nodes;
  };
  std::map<std::string_view, std::map<std::string_view, PortEntry>> racks;
  for (const auto& r : ports) racks[view(r.port->rack)][view(r.port->port)].row = &r;
  for (const auto& r : nodes) racks[view(r.node->rack)][view(r.node->port)].nodes.push_back(&r);

  out.begin_object().key("racks").begin_array();
  for (auto& [rack, rack_ports] : racks) {
    bool alive = false;
    for (auto& [name, e] : rack_ports) {
      if (e.row && e.row->alive) alive = true;
      for (const auto* n : e.nodes) alive = alive || n->alive;
    }
    out.begin_object().field("rack", rack).field("bridge_alive", alive).key("ports").begin_array();
    for (auto& [name, e] : rack_ports) {
      out.begin_object();
      if (e.row) {
        port_json_members(out, *e.row->port);
      } else {
        out.field("port", name);
      }
      std::sort(e.nodes.begin(), e.nodes.end(),
                [](const NodeRow* a, const NodeRow* b) { return a->node->mac < b->node->mac; });
      out.key("nodes").begin_array();
      for (const auto* n : e.nodes) node_row_record(*n).write(out);
      out.end_array().end_object();
    }
    out.end_array().end_object();
  }
  out.end_array().end_object();
}

}  // namespace dnbridge::dnbctl
