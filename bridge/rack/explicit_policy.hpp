#pragma once
// What the explicit gateway lets a remote requester do to a node the bridge
// is master of. The gateway is for reading and for commissioning, not a way
// around the bridge: by default it refuses the requests that would take the
// node's connections, its outputs or its configuration away from the bridge.
// Each class of such requests can be allowed per rack ([explicit_policy]);
// Gets are always allowed.
//
// The check looks at the request as it goes on the wire: a
// Set_Attribute_Single whose attribute comes as the first data byte is the
// same Set as one with the attribute given.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/devicenet/master/scan_list.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::rack {

// The requests the policy guards, one key of [explicit_policy] each.
enum class GuardedRequest : std::uint8_t {
  kAllocateRelease,        // Allocate/Release (0x4B/0x4C) to the DeviceNet object
  kConnectionChange,       // Set, Create, Delete, Apply_Attributes to the Connection object
  kOutputWrite,            // Set of a DOP/AOP Value or of Assembly data
  kManagedAttributeWrite,  // Set of an attribute the bridge configures
  kIdentityReset,          // Reset to the Identity object
  kNetworkSettings,        // Set of the DeviceNet object (MAC ID, bit rate, ...)
  kOtherService,           // a service the policy does not know (not Get, Set, Reset, ...)
};
inline constexpr std::size_t kGuardedRequestKinds = 7;

// Its [explicit_policy] key ("allow_identity_reset"), its name ("a device
// reset") and what it risks, for refusals and logs.
std::string_view policy_key(GuardedRequest kind) noexcept;
std::string_view name_of(GuardedRequest kind) noexcept;
std::string_view risk_of(GuardedRequest kind) noexcept;

// One rack's [explicit_policy]: everything refused unless allowed.
struct ExplicitPolicy {
  bool allow_allocate_release = false;
  bool allow_connection_changes = false;
  bool allow_output_writes = false;
  bool allow_managed_attribute_writes = false;
  bool allow_identity_reset = false;
  bool allow_network_settings = false;
  bool allow_other_services = false;

  bool allows(GuardedRequest kind) const noexcept;
  void allow(GuardedRequest kind, bool allowed) noexcept;
  friend bool operator==(const ExplicitPolicy&, const ExplicitPolicy&) = default;
};

// A request the policy refuses: its class, and a message saying which
// request it is, why it is refused and which key allows it.
struct PolicyRefusal {
  GuardedRequest kind;
  std::string message;
};

// What the policy knows of the node a request is for.
struct PolicyNode {
  // The attributes the bridge makes equal to its configuration at start-up
  // (the node profile's settings).
  std::span<const devicenet::AttributeSetting> managed;
};

// A class of guarded request that `request` belongs to, with a description
// of the request ("Release_Master/Slave_Connection_Set (0x4C) to the
// DeviceNet object").
struct Guarded {
  GuardedRequest kind;
  std::string what;
};
// Every class `request` belongs to, in the order of GuardedRequest (a
// Set_Attributes_All of an output point can write its Value and its
// fault/idle attributes at once). Empty for what is allowed whatever the
// policy: every Get, and Sets and Resets of what the bridge neither runs nor
// configures. Managed attributes are guarded in every state the gateway
// reaches a node in: a write during its start-up would land after the
// bridge's own read-back.
std::vector<Guarded> classify(const devicenet::RequestMessage& request, const PolicyNode& node);

// nullopt when `policy` lets `request` through.
std::optional<PolicyRefusal> check(const ExplicitPolicy& policy,
                                   const devicenet::RequestMessage& request,
                                   const PolicyNode& node);

}  // namespace dnbridge::rack
