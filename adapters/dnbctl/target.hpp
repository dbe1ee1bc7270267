#pragma once
// Finding what a command names: the node (rack, port, MAC) a pump or show
// command acts on, the port an explicit request goes through. The state
// topics are transient-local, so a bridge's current state arrives as soon
// as it is discovered; a short settling time after the first match lets
// other bridges (racks) with the same MAC be heard before choosing.
#include <cstdint>

#include "adapters/dnbctl/client.hpp"
#include "adapters/dnbctl/options.hpp"

namespace dnbridge::dnbctl {

// After the first match, how long other racks get to be heard.
inline constexpr Duration kSettle = milliseconds(300);

// The one node with this MAC among the racks and ports the options allow.
// Throws CommandError: kNotFound when none answered within the timeout,
// kUsage when several match (give --rack or --port).
NodeKey find_node(Client& client, const GlobalOptions& options, std::uint8_t mac);

// The port through which to address `mac`: the one whose bridge has the
// node configured, or else the only port there is (its bridge then answers
// "not in scan list"). Throws CommandError as find_node.
PortKey find_port(Client& client, const GlobalOptions& options, std::uint8_t mac);

}  // namespace dnbridge::dnbctl
