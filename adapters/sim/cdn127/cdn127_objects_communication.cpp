// What every DeviceNet slave has, as the CDN127 has it: Identity, Message
// Router, DeviceNet, Assembly and Connection (classes 0x01 to 0x05).
#include <array>

#include "adapters/sim/cdn127/cdn127_objects_internal.hpp"
#include "adapters/sim/generic/attribute_codec.hpp"
#include "adapters/sim/generic/connection_object.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim::cdn127_objects_detail {

using cip::GeneralStatus;

// ---------------------------------------------------------------------------
// Identity, class 0x01.

constexpr ClassAttributeDef kIdentityClass[] = {{1, 1}, {2, 1}, {6, 7}, {7, 7}};

const AttributeDef kIdentityAttributes[] = {
    {1, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept {
       return put_u16(w, profiles::cdn127::kVendorId);
     },
     nullptr},
    {2, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept {
       return put_u16(w, profiles::cdn127::kProductType);
     },
     nullptr},
    {3, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept {
       return put_u16(w, profiles::cdn127::kProductCode);
     },
     nullptr},
    {4, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       w.u8(c.device.options().revision_major);
       w.u8(c.device.options().revision_minor);
       return kReplyOk;
     },
     nullptr},
    {5, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u16(w, c.device.identity_status());
     },
     nullptr},
    {6, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       // UINT per the manual's table; UDINT as an option (ODVA Identity).
       const std::uint32_t serial = c.device.options().serial_number;
       if (c.device.options().serial_number_udint) {
         w.u32le(serial);
       } else {
         w.u16le(static_cast<std::uint16_t>(serial & 0xFFFF));
       }
       return kReplyOk;
     },
     nullptr},
    {7, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept { return put_short_string(w, "CDN127"); },
     nullptr},
    {8, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.identity_state());
     },
     nullptr},
};

// Reset type 0 (or no data): emulate a power cycle; 1: back to the
// out-of-box settings first. Done once the response is sent.
Reply identity_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  if (data.size() > 1) return reply_error(GeneralStatus::kTooMuchData);
  const std::uint8_t type = data.empty() ? 0 : data[0];
  if (type > 1) return reply_error(GeneralStatus::kInvalidParameter);
  c.device.request_action(type == 0 ? PendingAction::kRestart
                                    : PendingAction::kRestartFactoryDefaults);
  return kReplyOk;
}

// ---------------------------------------------------------------------------
// Router, class 0x02: no class attribute 2 in its table.

constexpr ClassAttributeDef kRouterClass[] = {{1, 1}, {6, 7}, {7, 2}};

const AttributeDef kRouterAttributes[] = {
    {2, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u16(w, 2); },
     nullptr},
};

// ---------------------------------------------------------------------------
// DeviceNet, class 0x03.

constexpr ClassAttributeDef kDeviceNetClass[] = {{1, 2}};

namespace {

// Attributes 6..9 read a switch; in the program position the switch is "removed
// from the circuit": Attribute Not Supported (manual, attributes 6..9).
Reply mac_switch_attr(const RequestContext& c, ByteWriter& w, bool changed) noexcept {
  const Cdn127Device& d = c.device;
  if (d.mac_switch_in_program_position()) return reply_error(GeneralStatus::kAttributeNotSupported);
  return put_u8(w, changed ? static_cast<std::uint8_t>(d.mac_switch_changed()) : d.mac_switch());
}
Reply baud_switch_attr(const RequestContext& c, ByteWriter& w, bool changed) noexcept {
  const Cdn127Device& d = c.device;
  if (d.baud_switch_in_program_position())
    return reply_error(GeneralStatus::kAttributeNotSupported);
  return put_u8(w, changed ? static_cast<std::uint8_t>(d.baud_switch_changed()) : d.baud_switch());
}

}  // namespace

const AttributeDef kDeviceNetAttributes[] = {
    {1, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.mac().value());
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       std::uint8_t v = 0;
       Reply r = read_u8(data, v);
       return r.ok() ? c.device.set_mac(v) : r;
     }},
    {2, Access::kGetSet,
     // The stored value: a new rate is used from the next power-up.
     [](const RequestContext& c, ByteWriter& w) noexcept { return put_u8(w, c.device.e2().baud); },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       std::uint8_t v = 0;
       Reply r = read_u8(data, v);
       return r.ok() ? c.device.set_baud(v) : r;
     }},
    {3, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.e2().bus_off_interrupt ? 1 : 0);
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       return read_bool(data, c.device.e2().bus_off_interrupt);
     }},
    {4, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.bus_off_counter());
     },
     // "forced to 0 whenever set regardless of the data value provided"
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       std::uint8_t ignored = 0;
       Reply r = read_u8(data, ignored);
       if (r.ok()) c.device.clear_bus_off_counter();
       return r;
     }},
    {5, Access::kGet,  // "Get/Spc": changed only by Allocate and Release
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_allocation_information(c.device.connections(), w);
     },
     nullptr},
    {6, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return mac_switch_attr(c, w, true); },
     nullptr},
    {7, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return baud_switch_attr(c, w, true); },
     nullptr},
    {8, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return mac_switch_attr(c, w, false); },
     nullptr},
    {9, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return baud_switch_attr(c, w, false); },
     nullptr},
};

Reply devicenet_allocate(const RequestContext& c, Bytes data, ByteWriter& w) noexcept {
  return allocate_service(c.device.connections(), data, c.now, w);
}
Reply devicenet_release(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  return release_service(c.device.connections(), data, c.requester, c.now);
}

// ---------------------------------------------------------------------------
// Assembly, class 0x04: attribute 3 of instances 1, 2, 3, 101, 102, 103
// (produced, Get) and 5, 100, 104 (consumed, Get/Set).

constexpr ClassAttributeDef kAssemblyClass[] = {{1, 1}, {2, 100}};

bool assembly_exists(const Cdn127Device&, std::uint16_t i) noexcept {
  return is_produced_assembly(i) || is_consumed_assembly(i);
}

const AttributeDef kAssemblyAttributes[] = {
    {3, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       std::array<std::uint8_t, 8> buf{};
       const auto inst = static_cast<std::uint8_t>(c.instance);
       const std::size_t n = is_consumed_assembly(inst) ? c.device.consumed_data(inst, buf)
                                                        : c.device.produced_data(inst, c.now, buf);
       w.bytes(Bytes(buf.data(), n));
       return kReplyOk;
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       if (!is_consumed_assembly(c.instance))
         return reply_error(GeneralStatus::kAttributeNotSettable);
       return c.device.set_consumed_assembly(static_cast<std::uint8_t>(c.instance), data, c.now);
     }},
};

// ---------------------------------------------------------------------------
// Connection, class 0x05: instance 1 explicit, 2 poll (connection_object.hpp).

constexpr ClassAttributeDef kConnectionClass[] = {{1, 1}};

bool connection_exists(const Cdn127Device& d, std::uint16_t i) noexcept {
  return i <= connection_instance::kPoll && d.connections().exists(i);
}

namespace {

template <std::uint8_t Attribute>
Reply get_connection(const RequestContext& c, ByteWriter& w) noexcept {
  return get_connection_attribute(c.device.connections(), c.device.mac(), c.device, c.instance,
                                  Attribute, w);
}
template <std::uint8_t Attribute>
Reply set_connection(const RequestContext& c, Bytes data, ByteWriter& w) noexcept {
  return set_connection_attribute(c.device.connections(), c.device, c.instance, Attribute, data,
                                  c.now, w);
}

}  // namespace

// 12 is Get only on the explicit connection (manual: "fixed value"), unless
// SlaveOptions::explicit_timeout_action_settable; 17 is Get only.
const AttributeDef kConnectionAttributes[] = {
    {1, Access::kGet, get_connection<1>, nullptr},
    {2, Access::kGet, get_connection<2>, nullptr},
    {3, Access::kGet, get_connection<3>, nullptr},
    {4, Access::kGet, get_connection<4>, nullptr},
    {5, Access::kGet, get_connection<5>, nullptr},
    {6, Access::kGet, get_connection<6>, nullptr},
    {7, Access::kGet, get_connection<7>, nullptr},
    {8, Access::kGet, get_connection<8>, nullptr},
    {9, Access::kGetSet, get_connection<9>, set_connection<9>},
    {12, Access::kGetSet, get_connection<12>, set_connection<12>},
    {13, Access::kGet, get_connection<13>, nullptr},
    {14, Access::kGetSet, get_connection<14>, set_connection<14>},
    {15, Access::kGet, get_connection<15>, nullptr},
    {16, Access::kGetSet, get_connection<16>, set_connection<16>},
    {17, Access::kGet, get_connection<17>, nullptr},
};

Reply connection_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  return reset_connection(c.device.connections(), c.instance, data, c.now);
}

Reply connection_class_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  return reset_connection_class(c.device.connections(), data, c.now);
}

}  // namespace dnbridge::sim::cdn127_objects_detail
