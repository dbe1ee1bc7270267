#include "bridge/rack/explicit_policy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "bridge/cip/objects.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::rack {
namespace {

namespace cdn127 = profiles::cdn127;
using cip::Service;
using devicenet::AttributeSetting;
using devicenet::RequestMessage;

bool is(const RequestMessage& r, Service s) { return r.service == static_cast<std::uint8_t>(s); }

std::string service_name(const RequestMessage& r) {
  const auto name = cip::to_string(static_cast<Service>(r.service));
  if (name.empty()) return fmt::format("service 0x{:02X}", r.service);
  return fmt::format("{} (0x{:02X})", name, r.service);
}

// The attribute a Set_Attribute_Single writes, as the device reads it: the
// byte after the instance, which is the first data byte when the request
// gives no attribute of its own.
std::optional<std::uint8_t> set_attribute(const RequestMessage& r) {
  if (!is(r, Service::kSetAttributeSingle)) return std::nullopt;
  if (r.attribute) return r.attribute;
  if (!r.data.empty()) return static_cast<std::uint8_t>(r.data[0]);
  return std::nullopt;
}

// Set_Attributes_All writes every settable attribute of the instance.
bool writes_attribute(const RequestMessage& r, std::uint8_t attribute) {
  return is(r, Service::kSetAttributesAll) || set_attribute(r) == attribute;
}

std::optional<std::string> allocate_release(const RequestMessage& r) {
  if (r.class_id != devicenet::kDeviceNetClass) return std::nullopt;
  if (!is(r, Service::kAllocateMasterSlave) && !is(r, Service::kReleaseMasterSlave)) {
    return std::nullopt;
  }
  return fmt::format("{} to the DeviceNet object", service_name(r));
}

std::optional<std::string> connection_change(const RequestMessage& r) {
  if (r.class_id != cip::connection::kClass) return std::nullopt;
  // Delete, Create, Apply_Attributes and Reset change connections as much as
  // a Set (a Reset restarts the connection's watchdog, the CDN127 manual's
  // Connection object lists it).
  if (!is(r, Service::kSetAttributeSingle) && !is(r, Service::kSetAttributesAll) &&
      !is(r, Service::kCreate) && !is(r, Service::kDelete) && !is(r, Service::kApplyAttributes) &&
      !is(r, Service::kReset)) {
    return std::nullopt;
  }
  if (auto a = set_attribute(r)) {
    return fmt::format("{} of Connection instance {} attribute {}", service_name(r), r.instance_id,
                       *a);
  }
  return fmt::format("{} to Connection instance {}", service_name(r), r.instance_id);
}

std::optional<std::string> network_setting(const RequestMessage& r) {
  if (r.class_id != devicenet::kDeviceNetClass) return std::nullopt;
  if (!is(r, Service::kSetAttributeSingle) && !is(r, Service::kSetAttributesAll))
    return std::nullopt;
  if (auto a = set_attribute(r)) {
    return fmt::format("{} of DeviceNet object attribute {}", service_name(r), *a);
  }
  return fmt::format("{} to the DeviceNet object", service_name(r));
}

// The services the classes above judge, and the Gets; anything else (a
// Multiple_Service_Packet carrying requests of its own, Start/Stop,
// Save/Restore, a vendor's service) is not let through unknown.
std::optional<std::string> other_service(const RequestMessage& r) {
  for (Service known :
       {Service::kGetAttributeSingle, Service::kGetAttributesAll, Service::kSetAttributeSingle,
        Service::kSetAttributesAll, Service::kReset, Service::kCreate, Service::kDelete,
        Service::kApplyAttributes, Service::kAllocateMasterSlave, Service::kReleaseMasterSlave}) {
    if (is(r, known)) return std::nullopt;
  }
  return fmt::format("{} to class 0x{:02X} instance {}", service_name(r), r.class_id,
                     r.instance_id);
}

std::optional<std::string> identity_reset(const RequestMessage& r) {
  if (r.class_id != cip::identity::kClass || !is(r, Service::kReset)) return std::nullopt;
  return fmt::format("{} of the Identity object", service_name(r));
}

std::optional<std::string> output_write(const RequestMessage& r) {
  std::uint8_t value_attribute = 0;
  switch (r.class_id) {
    case cdn127::class_id::kDiscreteOutputPoint:
      value_attribute = cdn127::dop_attr::kValue;
      break;
    case cdn127::class_id::kAnalogOutputPoint:
      value_attribute = cdn127::aop_attr::kValue;
      break;
    case cdn127::class_id::kAssembly:
      value_attribute = cip::assembly_attr::kData;
      break;
    default:
      return std::nullopt;
  }
  const std::string_view object = cip::class_name(r.class_id);
  // Instance 0 is the class itself: its attribute 3 is not the value.
  if (r.instance_id == 0 || !writes_attribute(r, value_attribute)) return std::nullopt;
  return fmt::format("{} of {} instance {} {}", service_name(r), object, r.instance_id,
                     r.class_id == cdn127::class_id::kAssembly ? "data" : "Value");
}

std::optional<std::string> managed_write(const RequestMessage& r, const PolicyNode& node) {
  const auto in_instance = [&](const AttributeSetting& s) {
    return s.class_id == r.class_id && s.instance_id == r.instance_id;
  };
  if (const auto a = set_attribute(r)) {
    const auto it = std::find_if(
        node.managed.begin(), node.managed.end(),
        [&](const AttributeSetting& s) { return in_instance(s) && s.attribute == *a; });
    if (it == node.managed.end()) return std::nullopt;
    return fmt::format("{} of {}", service_name(r), it->name);
  }
  // Set_Attributes_All and Reset rewrite the instance's attributes (the
  // CDN127 Configuration object's Reset loads a preset over them).
  if (!is(r, Service::kSetAttributesAll) && !is(r, Service::kReset)) return std::nullopt;
  const auto first = std::find_if(node.managed.begin(), node.managed.end(), in_instance);
  if (first == node.managed.end()) return std::nullopt;
  const auto count = std::count_if(node.managed.begin(), node.managed.end(), in_instance);
  return fmt::format("{} of class 0x{:02X} instance {} ({}{})", service_name(r), r.class_id,
                     r.instance_id, first->name,
                     count > 1 ? fmt::format(" and {} more", count - 1) : std::string());
}

// Each kind of guarded request, in the order the enum and classify() list
// them: its key, its name, its risk, its switch and how to recognise it.
struct GuardDef {
  GuardedRequest kind;
  std::string_view key;
  std::string_view name;
  std::string_view risk;
  bool ExplicitPolicy::*allowed;
  std::optional<std::string> (*recognise)(const RequestMessage&, const PolicyNode&);
};

constexpr std::array<GuardDef, kGuardedRequestKinds> kGuards{{
    {GuardedRequest::kAllocateRelease, "allow_allocate_release",
     "an allocation or release of connections",
     "the node's connections are the bridge's: a Release drops them and the pump's outputs go "
     "to their idle or fault values until the bridge has reconnected; an Allocate takes "
     "connections the bridge does not run",
     &ExplicitPolicy::allow_allocate_release,
     [](const RequestMessage& r, const PolicyNode&) { return allocate_release(r); }},
    {GuardedRequest::kConnectionChange, "allow_connection_changes", "a connection change",
     "the bridge's connections run with the paths, sizes, expected packet rates and watchdog "
     "actions it set: a change can stop the I/O, or keep the device from noticing a lost master "
     "(an expected packet rate of 0 turns its watchdog off)",
     &ExplicitPolicy::allow_connection_changes,
     [](const RequestMessage& r, const PolicyNode&) { return connection_change(r); }},
    {GuardedRequest::kOutputWrite, "allow_output_writes", "an output write",
     "outputs belong to PumpCommand, whose DDS ownership decides who commands a pump: a direct "
     "write bypasses it, and can switch a pump that nobody commands",
     &ExplicitPolicy::allow_output_writes,
     [](const RequestMessage& r, const PolicyNode&) { return output_write(r); }},
    {GuardedRequest::kManagedAttributeWrite, "allow_managed_attribute_writes",
     "a write of an attribute the bridge manages",
     "the bridge decodes the node's I/O and sets its safe state with these values, read back "
     "during start-up: a change afterwards breaks decoding or the outputs' fault and idle "
     "behaviour, unseen, until the node restarts and the bridge writes its own back",
     &ExplicitPolicy::allow_managed_attribute_writes,
     [](const RequestMessage& r, const PolicyNode& n) { return managed_write(r, n); }},
    {GuardedRequest::kIdentityReset, "allow_identity_reset", "a device reset",
     "the device restarts: its outputs go to their power-up state and the pump is lost until "
     "the bridge has brought it online again",
     &ExplicitPolicy::allow_identity_reset,
     [](const RequestMessage& r, const PolicyNode&) { return identity_reset(r); }},
    {GuardedRequest::kNetworkSettings, "allow_network_settings",
     "a change of the node's network settings",
     "a new MAC ID or bit rate takes the node off this port at its next restart, or puts it at "
     "another scan-list entry's address, where the bridge would command the wrong pump unless "
     "that entry pins a serial number",
     &ExplicitPolicy::allow_network_settings,
     [](const RequestMessage& r, const PolicyNode&) { return network_setting(r); }},
    {GuardedRequest::kOtherService, "allow_other_services", "a service the policy does not know",
     "its effect is unknown to the bridge: it may carry requests of its own "
     "(Multiple_Service_Packet) or change the device in ways no other key covers",
     &ExplicitPolicy::allow_other_services,
     [](const RequestMessage& r, const PolicyNode&) { return other_service(r); }},
}};

constexpr bool in_enum_order() {
  for (std::size_t i = 0; i < kGuards.size(); ++i) {
    if (static_cast<std::size_t>(kGuards[i].kind) != i) return false;
  }
  return true;
}
static_assert(in_enum_order(), "kGuards lists the kinds in the order of GuardedRequest");

const GuardDef& guard(GuardedRequest kind) noexcept {
  return kGuards[static_cast<std::size_t>(kind)];
}

}  // namespace

std::string_view policy_key(GuardedRequest kind) noexcept { return guard(kind).key; }
std::string_view name_of(GuardedRequest kind) noexcept { return guard(kind).name; }
std::string_view risk_of(GuardedRequest kind) noexcept { return guard(kind).risk; }

bool ExplicitPolicy::allows(GuardedRequest kind) const noexcept {
  return this->*guard(kind).allowed;
}

void ExplicitPolicy::allow(GuardedRequest kind, bool allowed) noexcept {
  this->*guard(kind).allowed = allowed;
}

std::vector<Guarded> classify(const RequestMessage& request, const PolicyNode& node) {
  std::vector<Guarded> out;
  for (const GuardDef& g : kGuards) {
    if (auto what = g.recognise(request, node)) out.push_back({g.kind, std::move(*what)});
  }
  return out;
}

std::optional<PolicyRefusal> check(const ExplicitPolicy& policy, const RequestMessage& request,
                                   const PolicyNode& node) {
  for (auto& g : classify(request, node)) {
    if (policy.allows(g.kind)) continue;
    return PolicyRefusal{
        g.kind, fmt::format("{} is {}, which the explicit policy refuses. Risk: {}. {} = true in "
                            "[explicit_policy] allows it",
                            g.what, name_of(g.kind), risk_of(g.kind), policy_key(g.kind))};
  }
  return std::nullopt;
}

}  // namespace dnbridge::rack
