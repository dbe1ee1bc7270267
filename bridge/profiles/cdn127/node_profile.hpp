#pragma once
// What the master must know to bring a CDN127 online: its identity, the
// Configuration object values, its outputs' safe state, the poll
// connection's paths and sizes.
#include "bridge/common/result.hpp"
#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/profiles/cdn127/safe_state.hpp"

namespace dnbridge::profiles::cdn127 {

// The safe state a node's outputs are given, or the device's own kept.
struct SafeStateConfig {
  SafeState values;
  SafeStateSource source = SafeStateSource::kConfiguration;

  friend bool operator==(const SafeStateConfig&, const SafeStateConfig&) = default;
};

// The poll connection uses assemblies 103 (produced) and 104 (consumed),
// whose formats follow the Configuration object; the master sets that object
// to `config`, then the outputs' fault and idle actions to `safe` (only the
// attributes that differ, each read back) before starting the connection.
// Fails on an invalid configuration.
Result<devicenet::NodeProfile> make_node_profile(const IoConfiguration& config,
                                                 const SafeStateConfig& safe);

}  // namespace dnbridge::profiles::cdn127
