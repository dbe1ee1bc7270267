#pragma once
// `dnbctl racks`: every rack's bridge on the domain and, per rack, how many
// of its nodes are online, idle, faulted, owned by another master, ... and
// why those that are not online are not. Pure functions of what the client
// read (PortStatus, NodeStatus, PumpState, and the bridges' participants).
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/dnbctl/format.hpp"
#include "adapters/dnbctl/json.hpp"

namespace dnbridge::dnbctl {

// What an operator needs to know of a node, one class each.
enum class NodeClass : std::uint8_t {
  kOnline,       // polled; its outputs are the commanded ones (or held)
  kIdle,         // polled idle: no commander, the device applies its own idle outputs
  kStarting,     // identifying, configuring or verifying
  kAbsent,       // not answering
  kFaulted,      // wrong device or configuration fault: not polled
  kOtherMaster,  // owned by another DeviceNet master: not polled
  kStopped,      // released by the bridge (shutdown)
  kUnknown,      // no bridge publishes it any more: its last word only
};
inline constexpr std::size_t kNodeClasses = 8;

std::string_view to_text(NodeClass c);    // "online", "owned by another master", ...
std::string_view json_name(NodeClass c);  // "online", "owned_by_other_master", ...

NodeClass classify(const NodeRow& row);
// Why the node is in its class: the bridge's reason for its last transition,
// with what helps an operator act (idle: no commander; absent: Allocate
// attempts and the last error; unknown: the last state reported).
std::string class_reason(const NodeRow& row);
// A node as `racks` shows it: its class and why.
Record rack_node_record(const NodeRow& row);

enum class BridgeState : std::uint8_t {
  kLive,    // its participant is on the domain, or its instances are alive
  kSilent,  // its participant is on the domain, but nothing it publishes has arrived
  kGone,    // only the last word of a bridge that left
};
std::string_view to_text(BridgeState s);  // "live", "no status yet", "gone"

struct RackSummary {
  std::string rack;
  BridgeState bridge = BridgeState::kLive;
  unsigned participants = 0;          // live participants named "dnbridge <rack>"
  std::vector<std::string> hosts;     // where each runs ("HOST (pid PID)", "" unknown)
  std::vector<const PortRow*> ports;  // by port name
  std::vector<const NodeRow*> nodes;  // by port name, then MAC
  std::array<unsigned, kNodeClasses> counts{};
  unsigned count(NodeClass c) const { return counts[static_cast<std::size_t>(c)]; }
};

// One summary per rack, sorted by name. `participants`: the live bridge
// participants per rack name, with where each runs (Bridges::live; racks
// that publish nothing yet appear through them alone).
std::vector<RackSummary> summarize_racks(
    std::span<const PortRow> ports, std::span<const NodeRow> nodes,
    const std::map<std::string, std::vector<std::string>>& participants);

// The racks' table (counts per class), the ports that are not running on a
// healthy bus, and every node that is not online, with its reason.
std::string racks_text(std::span<const RackSummary> racks);
// {"racks": [{"rack", "bridge", "participants", "counts": {...}, "ports": [...],
//             "nodes": [{..., "class", "reason", ...}]}]}: every node, with its class.
void racks_json(JsonWriter& out, std::span<const RackSummary> racks);

}  // namespace dnbridge::dnbctl
