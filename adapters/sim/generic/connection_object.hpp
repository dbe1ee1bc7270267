#pragma once
// The Connection object (class 0x05) and the DeviceNet object's Allocate and
// Release of a simulated Group 2 only slave, over its ConnectionSet: what is
// the same in every such device. What differs per device (the sizes of its
// I/O data, the assemblies its paths may name) it says through IoAssemblies.
//
// Instance attributes (bridge/PROTOCOL.md §8): 1 state, 2 instance type,
// 3 transport class trigger, 4/5 produced/consumed connection ID (§1),
// 6 initial communication characteristics, 7/8 sizes, 9 expected packet rate
// (Set answers the rate kept, §7), 12 watchdog timeout action, 13..16 path
// lengths and paths (Assembly class 4, attribute 3; the explicit connection's
// are empty; settable while Configuring), 17 production inhibit time.
// The change-of-state / cyclic connection (instance 4) produces on Group 1
// message 13 and consumes the master's acknowledgments on Group 2 message 2
// (devicenet-facts §1, [RA 825-P]); its transport class trigger is this
// simulator's reading: client, production trigger cyclic (0) or change of
// state (1), class 2, or class 0 with acknowledgment suppressed.
#include <cstdint>

#include "adapters/sim/generic/connection_set.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"

namespace dnbridge::sim {

class IoAssemblies {
 public:
  // Connection attributes 7/8 of an instance (the explicit one's too).
  virtual std::uint16_t connection_size(std::uint16_t instance, bool produced) const noexcept = 0;
  // Whether a path may name `assembly` as the produced (consumed) data of
  // the I/O connection `instance`.
  virtual bool assembly_allowed(std::uint16_t instance, bool produced,
                                std::uint16_t assembly) const noexcept = 0;
  // The highest instance a path may name at all.
  virtual std::uint32_t max_assembly() const noexcept { return 0xFFFF; }
  // Attributes 14/16 Get only: a Set answers 0x0E.
  virtual bool paths_fixed() const noexcept { return false; }

 protected:
  ~IoAssemblies() = default;
};

// Whether the object has the attribute, and whether it is settable (9, 12,
// 14; 16 but on the change-of-state connection, which consumes no data; 17
// on the change-of-state connection).
bool connection_attribute_exists(std::uint8_t attribute) noexcept;
bool connection_attribute_settable(std::uint16_t instance, std::uint8_t attribute) noexcept;

// Get and Set of an existing instance's attribute; `w` takes the response
// data (a Set of attribute 9 answers the rate kept).
Reply get_connection_attribute(const ConnectionSet& set, devicenet::MacId mac,
                               const IoAssemblies& io, std::uint16_t instance,
                               std::uint8_t attribute, ByteWriter& w) noexcept;
Reply set_connection_attribute(ConnectionSet& set, const IoAssemblies& io, std::uint16_t instance,
                               std::uint8_t attribute, Bytes data, TimePoint now,
                               ByteWriter& w) noexcept;

// Connection Reset of one instance (no data), and of the class (every
// existing instance).
Reply reset_connection(ConnectionSet& set, std::uint16_t instance, Bytes data,
                       TimePoint now) noexcept;
Reply reset_connection_class(ConnectionSet& set, Bytes data, TimePoint now) noexcept;

// The DeviceNet object's services (bridge/PROTOCOL.md §3): Allocate
// [choice][allocator MAC] -> [reserved:4 | body format:4] (8/8 here), Release
// [choice] -> no data, the requester being the header's MAC.
Reply allocate_service(ConnectionSet& set, Bytes data, TimePoint now, ByteWriter& w) noexcept;
Reply release_service(ConnectionSet& set, Bytes data, std::uint8_t requester,
                      TimePoint now) noexcept;
// DeviceNet object attribute 5: {allocation choice, master MAC (255: none)}.
Reply put_allocation_information(const ConnectionSet& set, ByteWriter& w) noexcept;

}  // namespace dnbridge::sim
