// list, racks and show: what the bridges report about their ports and nodes.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/bridges.hpp"
#include "adapters/dnbctl/commands.hpp"
#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/rack_summary.hpp"
#include "adapters/dnbctl/target.hpp"
#include "adapters/dnbctl/values.hpp"

namespace dnbridge::dnbctl {

Client make_client(const GlobalOptions& options) {
  return Client(
      options.domain, fmt::format("dnbctl {}:{}", user_at_host(), getpid()),
      options.security ? security::participant_properties(*options.security) : dds::Properties{});
}

void print(const std::string& text) {
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
}

namespace {

// Every port the options allow has all its configured nodes in both node
// topics: nothing more is expected from the bridges heard so far.
bool complete(const Client& client, const GlobalOptions& o) {
  for (const auto& [key, port] : client.ports()) {
    if (!o.matches(key.rack, key.port)) continue;
    std::size_t nodes = 0;
    std::size_t states = 0;  // PumpState and DeviceState
    for (const auto& [k, n] : client.nodes()) nodes += (k.rack == key.rack && k.port == key.port);
    for (const auto& [k, p] : client.pumps()) states += (k.rack == key.rack && k.port == key.port);
    for (const auto& [k, d] : client.devices())
      states += (k.rack == key.rack && k.port == key.port);
    if (nodes < port.data->nodes_configured || states < port.data->nodes_configured) return false;
  }
  return true;
}

}  // namespace

bool any_port(const Client& client, const GlobalOptions& o) {
  for (const auto& [key, port] : client.ports()) {
    if (o.matches(key.rack, key.port)) return true;
  }
  return false;
}

// Waits as list and racks do: until `found` (else kNotFound), then kSettle
// for other bridges to be heard, then until nothing is `missing` or the
// timeout (then a note on stderr says what is missing; what was heard is
// shown all the same).
void gather(Client& client, const GlobalOptions& o, const std::function<bool()>& found,
            const std::function<std::string()>& missing) {
  const Deadline deadline = deadline_after(o.timeout());
  if (!client.wait_until(deadline, found)) {
    throw CommandError(
        Exit::kNotFound,
        fmt::format("no bridge answered on DDS domain {}{} within {:g} s{}", o.domain,
                    o.rack.empty() ? "" : fmt::format(" for rack \"{}\"", o.rack),
                    o.timeout_seconds, no_bridge_causes(client, o)));
  }
  const Deadline settle = std::min(deadline, deadline_after(kSettle));
  client.wait_until(settle, [] { return false; });
  if (!client.wait_until(deadline, [&] { return missing().empty(); })) {
    std::fprintf(stderr, "dnbctl: note: %s within the timeout\n", missing().c_str());
  }
}

std::string nodes_missing(const Client& client, const GlobalOptions& o) {
  return complete(client, o) ? std::string() : "not every configured node was reported";
}

namespace {

// The rows list and racks show: what the options allow.
std::vector<PortRow> port_rows(const Client& client, const GlobalOptions& o) {
  std::vector<PortRow> ports;
  for (const auto& [k, p] : client.ports()) {
    if (o.matches(k.rack, k.port)) ports.push_back({p.data.get(), p.alive});
  }
  return ports;
}

}  // namespace

std::vector<NodeRow> node_rows(const Client& client, const GlobalOptions& o) {
  std::vector<NodeRow> nodes;
  for (const auto& [k, n] : client.nodes()) {
    if (!o.matches(k.rack, k.port)) continue;
    const auto* pump = client.pump(k);
    const auto* device = client.device(k);
    nodes.push_back({n.data.get(), pump ? pump->data.get() : nullptr, n.alive,
                     device ? device->data.get() : nullptr});
  }
  return nodes;
}

CLI::App* add_list(CLI::App& app, ListArgs& args) {
  auto* cmd = app.add_subcommand(
      "list",
      "List the bridges (racks) and their ports (state, bus load, nodes online), and the nodes "
      "(life-cycle state, reason, name, product, online). Both tables by default; --json gives "
      "both, as racks > ports > nodes.");
  auto* nodes = cmd->add_flag("--nodes", args.nodes_only, "Only the nodes' table");
  auto* ports = cmd->add_flag("--ports", args.ports_only, "Only the ports' table");
  nodes->excludes(ports);
  return cmd;
}

Exit run_list(const GlobalOptions& o, const ListArgs& args) {
  Client client = make_client(o);
  const auto found = [&] { return any_port(client, o); };
  gather(client, o, found, [&] { return nodes_missing(client, o); });

  const std::vector<PortRow> ports = port_rows(client, o);
  const std::vector<NodeRow> nodes = node_rows(client, o);

  if (o.json) {
    JsonWriter out;
    list_json(out, ports, nodes);
    print(out.str() + "\n");
    return Exit::kOk;
  }
  std::string text;
  if (!args.nodes_only) text += ports_table(ports);
  if (!args.nodes_only && !args.ports_only) text += "\n";
  if (!args.ports_only) text += nodes_table(nodes);
  print(text);
  return Exit::kOk;
}

CLI::App* add_racks(CLI::App& app) {
  return app.add_subcommand(
      "racks",
      "Find every bridge on the domain and summarize each rack: its bridge (live, no status yet, "
      "gone), ports running, and how many nodes are online, idle (no command in force), starting, "
      "absent, faulted (wrong device, configuration fault, device fault), owned by another master, "
      "stopped or "
      "unknown (no longer published); then the ports that need attention and every node that is "
      "not online, with the reason. A bridge is found by its participant (\"dnbridge <rack>\") "
      "even before it publishes anything. --json gives every node with its class.");
}

Exit run_racks(const GlobalOptions& o) {
  Client client = make_client(o);
  Bridges bridges(client);
  const auto bridge_racks = [&] {
    bridges.refresh();
    auto racks = bridges.live();
    std::erase_if(racks, [&](const auto& r) { return !o.rack.empty() && r.first != o.rack; });
    return racks;
  };
  const auto has_status = [&](const std::string& rack) {
    for (const auto& [k, p] : client.ports()) {
      if (k.rack == rack) return true;
    }
    return false;
  };
  gather(
      client, o, [&] { return any_port(client, o) || !bridge_racks().empty(); },
      [&] {
        std::string silent;
        for (const auto& [rack, count] : bridge_racks()) {
          if (!has_status(rack)) silent += (silent.empty() ? "" : ", ") + rack;
        }
        if (!silent.empty()) return "no status from the bridge of " + silent;
        return nodes_missing(client, o);
      });

  const std::vector<PortRow> ports = port_rows(client, o);
  const std::vector<NodeRow> nodes = node_rows(client, o);
  const std::vector<RackSummary> racks = summarize_racks(ports, nodes, bridge_racks());
  if (o.json) {
    JsonWriter out;
    racks_json(out, racks);
    print(out.str() + "\n");
  } else {
    print(racks_text(racks));
  }
  return Exit::kOk;
}

CLI::App* add_show(CLI::App& app, ShowArgs& args) {
  auto* cmd = app.add_subcommand(
      "show",
      "Show one node: identity (vendor, product type and code, revision, serial number, product "
      "name), life-cycle state and reason, device state, poll sizes, expected packet rate, last "
      "error, last refused command, and counters (NodeStatus); for a device of profile \"eds\" "
      "also its inputs and outputs as bytes and as its EDS's fields (DeviceState).");
  cmd->add_option("NODE", args.node, "The node: its MAC ID (0..63) or its name")->required();
  return cmd;
}

Exit run_show(const GlobalOptions& o, const ShowArgs& args) {
  auto ref = parse_node(args.node);
  if (!ref) throw CommandError(Exit::kUsage, ref.error());
  Client client = make_client(o);
  const NodeKey key = find_node(client, o, *ref);
  if (!client.wait_until(deadline_after(o.timeout()),
                         [&] { return client.node(key) != nullptr; })) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("{}: no NodeStatus within {:g} s",
                                   node_name(key.rack, key.port, key.mac), o.timeout_seconds));
  }
  const auto* node = client.node(key);
  const auto* pump = client.pump(key);
  const dnbridge_PumpState* state = pump ? pump->data.get() : nullptr;
  const auto* device = client.device(key);
  const dnbridge_DeviceState* data = device ? device->data.get() : nullptr;
  if (o.json) {
    JsonWriter out;
    node_json(out, *node->data, state, node->alive, data);
    print(out.str() + "\n");
  } else {
    print(node_details(*node->data, state, node->alive, data));
  }
  return Exit::kOk;
}

}  // namespace dnbridge::dnbctl
