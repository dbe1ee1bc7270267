#pragma once
// What the master must know to bring a CDN127 online: its identity, the
// Configuration object values, the poll connection's paths and sizes.
#include "bridge/common/result.hpp"
#include "bridge/devicenet/scan_list.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::profiles::cdn127 {

// The poll connection uses assemblies 103 (produced) and 104 (consumed),
// whose formats follow the Configuration object; the master sets that object
// to `config` (only the attributes that differ) before starting the
// connection. Fails on an invalid configuration.
Result<devicenet::NodeProfile> make_node_profile(const IoConfiguration& config);

}  // namespace dnbridge::profiles::cdn127
