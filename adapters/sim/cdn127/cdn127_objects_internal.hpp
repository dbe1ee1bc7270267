#pragma once
// What the parts of the CDN127 object model share. Each class's tables and
// handlers are defined with the class: Identity, Message Router, DeviceNet,
// Assembly and Connection in cdn127_objects_communication.cpp; the Discrete
// and Analog Input and Output Points in cdn127_objects_points.cpp; Device
// Supervisor and Configuration in cdn127_objects_device.cpp. The class table
// (cdn127_objects.cpp) names them; the helper handlers of several classes
// use is defined there too.
//
// A table's bound here is its number of entries, so that the class table
// can take its size: a table given more entries does not compile, one given
// fewer would end in empty entries (EveryListedAttributeAnswersGet, in
// tests/sim/cdn127, finds those of instance attributes).
#include <cstdint>
#include <string_view>

#include "adapters/sim/cdn127/cdn127_device.hpp"
#include "adapters/sim/cdn127/cdn127_objects.hpp"
#include "bridge/common/bytes.hpp"

namespace dnbridge::sim::cdn127_objects_detail {

// Helpers for attribute handlers (cdn127_objects.cpp).
Reply put_short_string(ByteWriter& w, std::string_view text) noexcept;

// Identity, class 0x01.
extern const ClassAttributeDef kIdentityClass[4];
extern const AttributeDef kIdentityAttributes[8];
Reply identity_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept;

// Router, class 0x02.
extern const ClassAttributeDef kRouterClass[3];
extern const AttributeDef kRouterAttributes[1];

// DeviceNet, class 0x03.
extern const ClassAttributeDef kDeviceNetClass[1];
extern const AttributeDef kDeviceNetAttributes[9];
Reply devicenet_allocate(const RequestContext& c, Bytes data, ByteWriter& w) noexcept;
Reply devicenet_release(const RequestContext& c, Bytes data, ByteWriter&) noexcept;

// Assembly, class 0x04.
extern const ClassAttributeDef kAssemblyClass[2];
extern const AttributeDef kAssemblyAttributes[1];
bool assembly_exists(const Cdn127Device&, std::uint16_t i) noexcept;

// Connection, class 0x05.
extern const ClassAttributeDef kConnectionClass[1];
extern const AttributeDef kConnectionAttributes[15];
bool connection_exists(const Cdn127Device& d, std::uint16_t i) noexcept;
Reply connection_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept;
Reply connection_class_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept;

// Discrete Input Point, class 0x08.
extern const ClassAttributeDef kDipClass[4];
extern const AttributeDef kDipAttributes[2];
bool dip_exists(const Cdn127Device&, std::uint16_t i) noexcept;

// Discrete Output Point, class 0x09.
extern const ClassAttributeDef kDopClass[4];
extern const AttributeDef kDopAttributes[6];
bool dop_exists(const Cdn127Device&, std::uint16_t i) noexcept;

// Analog Input Point, class 0x0A.
extern const ClassAttributeDef kAipClass[4];
extern const AttributeDef kAipAttributes[4];
bool aip_exists(const Cdn127Device&, std::uint16_t i) noexcept;

// Analog Output Point, class 0x0B.
extern const ClassAttributeDef kAopClass[4];
extern const AttributeDef kAopAttributes[7];

// Device Supervisor, class 0x32.
extern const ClassAttributeDef kSupervisorClass[4];
extern const AttributeDef kSupervisorAttributes[12];

// Configuration, class 0x40.
extern const ClassAttributeDef kConfigurationClass[4];
extern const AttributeDef kConfigurationAttributes[8];
Reply configuration_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept;

}  // namespace dnbridge::sim::cdn127_objects_detail
