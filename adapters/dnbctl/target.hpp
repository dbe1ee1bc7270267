#pragma once
// Finding what a command names: the node (rack, port, MAC) a pump or show
// command acts on, the port an explicit request goes through. The state
// topics are transient-local, so a bridge's current state arrives as soon
// as it is discovered; a short settling time after the first match lets
// other bridges (racks) with the same MAC be heard before choosing.
#include <cstdint>

#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/options.hpp"
#include "adapters/dnbctl/values.hpp"

namespace dnbridge::dnbctl {

// After the first match, how long other racks get to be heard.
inline constexpr Duration kSettle = milliseconds(300);

// When `client` heard no bridge at all, what to check: the domain and
// network configuration dnbctl used, and the usual causes (another domain,
// CYCLONEDDS_URI not reaching the bridge's network, a firewall, DDS Security
// on one side only). Lines to append to the error, each starting "\n  ";
// empty when a bridge was heard.
std::string no_bridge_causes(const Client& client, const GlobalOptions& options);

// The one node `ref` names (by MAC or by name) among the racks and ports the
// options allow. Throws CommandError: kNotFound when none answered within
// the timeout (with the closest name as a hint, for a name), kUsage when
// several match (give --rack or --port).
NodeKey find_node(Client& client, const GlobalOptions& options, const NodeRef& ref);

// Where to address an explicit request to `ref`: the port whose bridge has
// the node configured, or else, for a MAC, the only port there is (its
// bridge then answers "not in scan list"). Throws CommandError as find_node.
NodeKey find_port(Client& client, const GlobalOptions& options, const NodeRef& ref);

}  // namespace dnbridge::dnbctl
