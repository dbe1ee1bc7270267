#include "adapters/dnbctl/target.hpp"

#include <fmt/format.h>

#include <set>
#include <vector>

namespace dnbridge::dnbctl {
namespace {

std::string where(const GlobalOptions& o) {
  std::string w = fmt::format("on DDS domain {}", o.domain);
  if (!o.rack.empty()) w += fmt::format(", rack \"{}\"", o.rack);
  if (!o.port.empty()) w += fmt::format(", port \"{}\"", o.port);
  return w;
}

std::string seconds_text(const GlobalOptions& o) { return fmt::format("{:g} s", o.timeout_seconds); }

// The nodes with `mac` the options allow, from both node topics.
std::set<NodeKey> candidates(const Client& client, const GlobalOptions& o, std::uint8_t mac) {
  std::set<NodeKey> found;
  for (const auto& [k, v] : client.nodes()) {
    if (k.mac == mac && o.matches(k.rack, k.port)) found.insert(k);
  }
  for (const auto& [k, v] : client.pumps()) {
    if (k.mac == mac && o.matches(k.rack, k.port)) found.insert(k);
  }
  return found;
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

NodeKey find_node(Client& client, const GlobalOptions& o, std::uint8_t mac) {
  discover(client, o, [&] { return candidates(client, o, mac); });
  const auto found = candidates(client, o, mac);
  if (found.empty()) {
    throw CommandError(Exit::kNotFound,
                       fmt::format("no bridge reported a node with MAC {} {} within {}", mac,
                                   where(o), seconds_text(o)));
  }
  if (found.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("MAC {} is on more than one port ({}): give --rack and --port",
                                   mac, list_of(found)));
  }
  return *found.begin();
}

PortKey find_port(Client& client, const GlobalOptions& o, std::uint8_t mac) {
  discover(client, o, [&] { return candidate_ports(client, o); });
  const auto nodes = candidates(client, o, mac);
  if (nodes.size() == 1) return PortKey{nodes.begin()->rack, nodes.begin()->port};
  if (nodes.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("MAC {} is on more than one port ({}): give --rack and --port",
                                   mac, list_of(nodes)));
  }
  // No bridge has the node configured: the request goes to the only port
  // there is, whose bridge answers for it.
  const auto ports = candidate_ports(client, o);
  if (ports.empty()) {
    throw CommandError(Exit::kNotFound, fmt::format("no bridge answered {} within {}", where(o),
                                                    seconds_text(o)));
  }
  if (ports.size() > 1) {
    throw CommandError(Exit::kUsage,
                       fmt::format("no port has MAC {} configured and there are several ({}): "
                                   "give --rack and --port",
                                   mac, list_of(ports)));
  }
  return *ports.begin();
}

}  // namespace dnbridge::dnbctl
