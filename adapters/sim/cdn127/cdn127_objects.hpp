#pragma once
// The CDN127 object model as declarative tables, one per class: its class
// attributes, its instance attributes with their access, the services it
// lists at class and instance level, and which instances exist. Everything
// comes from the CDN127 DeviceNet Specifications rev 1.6 ("DeviceNet Object
// Classes" and the per-class tables); the message router below answers
// anything the tables do not list with the CIP error for it.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"

namespace dnbridge::sim {

enum class Access : std::uint8_t { kGet, kGetSet };

// What an attribute or service handler works on.
struct RequestContext {
  Cdn127Device& device;
  std::uint16_t instance;
  std::uint8_t requester;  // the master's MAC from the message header
  TimePoint now;
};

// A getter writes the attribute's value; a setter reads the request data and
// may write response data (an EPR set answers the value kept).
using AttributeGetter = Reply (*)(const RequestContext&, ByteWriter& out) noexcept;
using AttributeSetter = Reply (*)(const RequestContext&, Bytes data, ByteWriter& out) noexcept;
using ServiceHandler = Reply (*)(const RequestContext&, Bytes data, ByteWriter& out) noexcept;

struct AttributeDef {
  std::uint8_t id;
  Access access;
  AttributeGetter get;
  AttributeSetter set;  // nullptr for Get-only attributes; may refuse per instance
};

// Class attributes of the CDN127 are all UINT constants.
struct ClassAttributeDef {
  std::uint8_t id;
  std::uint16_t value;
};

struct ClassDef {
  std::uint8_t id;
  std::string_view name;  // cip::class_name for the common classes
  std::span<const ClassAttributeDef> class_attributes;
  std::span<const AttributeDef> instance_attributes;
  // Services the manual's "Common Services" table lists ("Class" / "Instance" columns).
  bool class_get;
  bool instance_get;
  bool instance_set;
  ServiceHandler class_reset;     // nullptr: not listed
  ServiceHandler instance_reset;  // nullptr: not listed
  ServiceHandler allocate;        // DeviceNet object only
  ServiceHandler release;         // DeviceNet object only
  bool (*has_instance)(const Cdn127Device&, std::uint16_t instance) noexcept;
};

// Every class the CDN127 implements, in class-code order.
std::span<const ClassDef> object_classes() noexcept;
const ClassDef* find_class(std::uint16_t class_id) noexcept;
const AttributeDef* find_attribute(const ClassDef& c, std::uint8_t attribute) noexcept;

// The message router: runs one explicit request and writes the response
// message (service byte first, success or error) into `out`, which should
// hold devicenet::kMaxExplicitMessage bytes. Returns the size written.
std::size_t execute_request(Cdn127Device& device, const devicenet::RequestMessage& request,
                            std::uint8_t requester, TimePoint now, MutableBytes out) noexcept;

}  // namespace dnbridge::sim
