#include "adapters/dnbctl/target.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dds/fields.hpp"
#include "bridge/common/closest.hpp"

namespace dnbridge::dnbctl {
namespace {

std::string where(const GlobalOptions& o) {
  std::string w = fmt::format("on DDS domain {}", o.domain);
  if (!o.rack.empty()) w += fmt::format(", rack \"{}\"", o.rack);
  if (!o.port.empty()) w += fmt::format(", port \"{}\"", o.port);
  return w;
}

std::string seconds_text(const GlobalOptions& o) {
  return fmt::format("{:g} s", o.timeout_seconds);
}

// `fn(key, name)` for every node the options allow, from both node topics
// (a node may be known from one only, so far).
template <class Fn>
void each_node(const Client& client, const GlobalOptions& o, Fn fn) {
  for (const auto& [k, v] : client.nodes()) {
    if (o.matches(k.rack, k.port)) fn(k, dds::view(v.data->name));
  }
  for (const auto& [k, v] : client.pumps()) {
    if (o.matches(k.rack, k.port)) fn(k, dds::view(v.data->name));
  }
}

// The nodes `ref` names that the options allow.
std::set<NodeKey> candidates(const Client& client, const GlobalOptions& o, const NodeRef& ref) {
  std::set<NodeKey> found;
  each_node(client, o, [&](const NodeKey& k, std::string_view name) {
    if (ref.matches(k.mac, name)) found.insert(k);
  });
  return found;
}

std::string described(const NodeRef& ref) {
  return ref.mac ? fmt::format("MAC {}", *ref.mac) : fmt::format("\"{}\"", ref.name);
}

// " (did you mean "pump-3"?)" when a node the options allow has a name
// close to the one given.
std::string name_hint(const Client& client, const GlobalOptions& o, const NodeRef& ref) {
  if (ref.mac) return {};
  std::vector<std::string_view> names;  // views into the client's samples
  each_node(client, o, [&](const NodeKey&, std::string_view name) { names.push_back(name); });
  const auto near = closest(ref.name, names, 3);
  return near ? fmt::format(" (did you mean \"{}\"?)", *near) : std::string{};
}

std::set<PortKey> candidate_ports(const Client& client, const GlobalOptions& o) {
  std::set<PortKey> found;
  for (const auto& [k, v] : client.ports()) {
    if (o.matches(k.rack, k.port)) found.insert(k);
  }
  return found;
}

std::string list_of(const std::set<NodeKey>& nodes) {
  std::string s;
  for (const auto& k : nodes) s += fmt::format("{}{}/{}", s.empty() ? "" : ", ", k.rack, k.port);
  return s;
}

std::string list_of(const std::set<PortKey>& ports) {
  std::string s;
  for (const auto& k : ports) s += fmt::format("{}{}/{}", s.empty() ? "" : ", ", k.rack, k.port);
  return s;
}

// Until `found()` is non-empty, then kSettle more unless the options name
// the rack and port exactly (nothing else can match then).
template <class Found>
void discover(Client& client, const GlobalOptions& o, Found found) {
  const Deadline deadline = deadline_after(o.timeout());
  if (!client.wait_until(deadline, [&] { return !found().empty(); })) return;
  if (!o.rack.empty() && !o.port.empty()) return;
  const Deadline settle = std::min(deadline, deadline_after(kSettle));
  client.wait_until(settle, [] { return false; });
}

}  // namespace

std::string no_bridge_causes(const Client& client, const GlobalOptions& o) {
  if (!client.ports().empty()) return {};  // a bridge was heard: DDS works
  const char* uri = std::getenv("CYCLONEDDS_URI");
  const bool uri_set = uri != nullptr && *uri != '\0';
  std::string s = fmt::format(
      "\n  dnbctl looked on DDS domain {} (--domain, $DNBCTL_DOMAIN) with {}.", o.domain,
      uri_set ? fmt::format("CYCLONEDDS_URI={}", uri)
              : std::string("no CYCLONEDDS_URI: Cyclone DDS's defaults, multicast discovery "
                            "on one network interface it chose"));
  s += "\n  Likely causes: no bridge runs on that domain (its configuration's `domain`);";
  s += uri_set ? "\n  this configuration does not reach the bridge's network (compare it with "
                 "the bridge's own, /etc/dnbridge/cyclonedds.xml on a bridge host);"
               : "\n  the bridge is pinned to another network: set CYCLONEDDS_URI as the "
                 "bridge's (file:///etc/dnbridge/cyclonedds.xml on a bridge host; "
                 "deploy/cyclonedds/loopback.xml for a simulated rack on this host);";
  s += fmt::format(
      "\n  a firewall drops DDS's UDP traffic (ports {} and up on this domain);"
      "\n  DDS Security on the bridge and not here, or the reverse (--security).",
      7400 + 250 * o.domain);
  return s;
}

NodeKey find_node(Client& client, const GlobalOptions& o, const NodeRef& ref) {
  discover(client, o, [&] { return candidates(client, o, ref); });
  const auto found = candidates(client, o, ref);
  if (found.empty()) {
    throw CommandError(
        Exit::kNotFound,
        fmt::format("no bridge reported a node {} {} {} within {}{}{}", ref.mac ? "with" : "named",
                    described(ref), where(o), seconds_text(o), name_hint(client, o, ref),
                    no_bridge_causes(client, o)));
  }
  if (found.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("{} is on more than one port ({}): give --rack and --port",
                                   described(ref), list_of(found)));
  }
  return *found.begin();
}

NodeKey find_port(Client& client, const GlobalOptions& o, const NodeRef& ref) {
  // A name must be a configured node's.
  if (!ref.mac) return find_node(client, o, ref);
  const std::uint8_t mac = *ref.mac;
  discover(client, o, [&] { return candidate_ports(client, o); });
  const auto nodes = candidates(client, o, ref);
  if (nodes.size() == 1) return *nodes.begin();
  if (nodes.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("MAC {} is on more than one port ({}): give --rack and --port",
                                   mac, list_of(nodes)));
  }
  // No bridge has the node configured: the request goes to the only port
  // there is, whose bridge answers for it.
  const auto ports = candidate_ports(client, o);
  if (ports.empty()) {
    throw CommandError(Exit::kNotFound, fmt::format("no bridge answered {} within {}{}", where(o),
                                                    seconds_text(o), no_bridge_causes(client, o)));
  }
  if (ports.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("no port has MAC {} configured and there are several ({}): "
                                   "give --rack and --port",
                                   mac, list_of(ports)));
  }
  return NodeKey{ports.begin()->rack, ports.begin()->port, mac};
}

}  // namespace dnbridge::dnbctl
