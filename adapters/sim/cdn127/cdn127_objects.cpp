#include "adapters/sim/cdn127/cdn127_objects.hpp"

#include <array>
#include <optional>
#include <string_view>

#include "adapters/sim/generic/attribute_codec.hpp"
#include "adapters/sim/generic/connection_object.hpp"
#include "bridge/cip/data_types.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim {
namespace {

using cip::GeneralStatus;
using profiles::cdn127::IoConfiguration;
using profiles::cdn127::PumpOutputs;
namespace cls = profiles::cdn127::class_id;

// ---------------------------------------------------------------------------
// Helpers for attribute handlers.

Reply put_short_string(ByteWriter& w, std::string_view text) noexcept {
  std::array<std::uint8_t, 1 + cip::kMaxShortStringLength> buf{};
  auto size = cip::encode_short_string(text, buf);
  if (!size.ok()) return reply_error(GeneralStatus::kReplyDataTooLarge);
  w.bytes(Bytes(buf.data(), *size));
  return kReplyOk;
}

// "XX.YYY" (manual, Device Supervisor attributes 7 and 8).
Reply put_revision_string(ByteWriter& w, std::uint8_t major, std::uint8_t minor) noexcept {
  std::array<char, 6> s{};
  s[0] = static_cast<char>('0' + (major / 10) % 10);
  s[1] = static_cast<char>('0' + major % 10);
  s[2] = '.';
  s[3] = static_cast<char>('0' + (minor / 100) % 10);
  s[4] = static_cast<char>('0' + (minor / 10) % 10);
  s[5] = static_cast<char>('0' + minor % 10);
  return put_short_string(w, std::string_view(s.data(), s.size()));
}

bool single_instance(const Cdn127Device&, std::uint16_t instance) noexcept { return instance == 1; }

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

// ---------------------------------------------------------------------------
// Discrete Input Point, class 0x08: instances 1..7, state as the poll byte
// reports it (NoNcMask applied), status 0.

constexpr ClassAttributeDef kDipClass[] = {{1, 2}, {2, 7}, {6, 7}, {7, 4}};

bool dip_exists(const Cdn127Device&, std::uint16_t i) noexcept { return i >= 1 && i <= 7; }

const AttributeDef kDipAttributes[] = {
    {3, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       c.device.pump().advance(c.now);
       const std::uint8_t bits =
           c.device.pump().inputs().encode(c.device.configuration().no_nc_mask);
       return put_u8(w, static_cast<std::uint8_t>((bits >> (c.instance - 1)) & 1));
     },
     nullptr},
    {4, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 0); },
     nullptr},
};

// ---------------------------------------------------------------------------
// Discrete Output Point, class 0x09: instance 1 Pump On (bit 0), instance 2
// N2 Ballast On (bit 2). Max Object Instance says 8; two exist.

constexpr ClassAttributeDef kDopClass[] = {{1, 1}, {2, 8}, {6, 7}, {7, 8}};

bool dop_exists(const Cdn127Device&, std::uint16_t i) noexcept { return i == 1 || i == 2; }

bool dop_output(const PumpOutputs& o, std::uint16_t instance) noexcept {
  return instance == 1 ? o.pump_on : o.n2_ballast_on;
}
DopSettings& dop_settings(const RequestContext& c) noexcept {
  return c.device.e2().dop[c.instance - 1u];
}

template <bool DopSettings::*Field>
Reply get_dop_setting(const RequestContext& c, ByteWriter& w) noexcept {
  return put_u8(w, dop_settings(c).*Field ? 1 : 0);
}
template <bool DopSettings::*Field>
Reply set_dop_setting(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  return read_bool(data, dop_settings(c).*Field);
}

const AttributeDef kDopAttributes[] = {
    {3, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, dop_output(c.device.pump().outputs(), c.instance) ? 1 : 0);
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       bool on = false;
       Reply r = read_bool(data, on);
       if (!r.ok()) return r;
       PumpOutputs o = c.device.pump().outputs();
       (c.instance == 1 ? o.pump_on : o.n2_ballast_on) = on;
       return c.device.set_outputs(o, OutputCause::kExplicit, c.now);
     }},
    {4, Access::kGet,  // a short circuit is the Identity's minor recoverable fault
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.faults().minor_recoverable ? 1 : 0);
     },
     nullptr},
    {5, Access::kGetSet, get_dop_setting<&DopSettings::fault_hold>,
     set_dop_setting<&DopSettings::fault_hold>},
    {6, Access::kGetSet, get_dop_setting<&DopSettings::fault_value>,
     set_dop_setting<&DopSettings::fault_value>},
    {7, Access::kGetSet, get_dop_setting<&DopSettings::idle_hold>,
     set_dop_setting<&DopSettings::idle_hold>},
    {8, Access::kGetSet, get_dop_setting<&DopSettings::idle_value>,
     set_dop_setting<&DopSettings::idle_value>},
};

// ---------------------------------------------------------------------------
// Analog Input Point, class 0x0A: instances 1..2, all attributes Get (the
// service table lists Set, which therefore answers Attribute Not Settable).

constexpr ClassAttributeDef kAipClass[] = {{1, 1}, {2, 2}, {6, 7}, {7, 8}};

bool aip_exists(const Cdn127Device&, std::uint16_t i) noexcept { return i == 1 || i == 2; }

const AttributeDef kAipAttributes[] = {
    {3, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u16(w, c.device.pump().analog_inputs_raw()[c.instance - 1u]);
     },
     nullptr},
    {4, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 0); },
     nullptr},
    {7, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 2); },
     nullptr},
    {8, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 0); },
     nullptr},
};

// ---------------------------------------------------------------------------
// Analog Output Point, class 0x0B: instance 1.

constexpr ClassAttributeDef kAopClass[] = {{1, 1}, {2, 1}, {6, 7}, {7, 12}};

template <std::uint8_t AopSettings::*Field>
Reply get_aop_state(const RequestContext& c, ByteWriter& w) noexcept {
  return put_u8(w, c.device.e2().aop.*Field);
}
template <std::uint8_t AopSettings::*Field>
Reply set_aop_state(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  std::uint8_t v = 0;
  Reply r = read_u8(data, v);
  if (!r.ok()) return r;
  if (v > 3) return reply_error(GeneralStatus::kInvalidAttributeValue);
  c.device.e2().aop.*Field = v;
  return kReplyOk;
}
template <std::uint16_t AopSettings::*Field>
Reply get_aop_value(const RequestContext& c, ByteWriter& w) noexcept {
  return put_u16(w, c.device.e2().aop.*Field);
}
template <std::uint16_t AopSettings::*Field>
Reply set_aop_value(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  std::uint16_t v = 0;
  Reply r = read_u16(data, v);
  if (!r.ok()) return r;
  if (v > profiles::cdn127::kAnalogMaxRaw)
    return reply_error(GeneralStatus::kInvalidAttributeValue);
  c.device.e2().aop.*Field = v;
  return kReplyOk;
}

const AttributeDef kAopAttributes[] = {
    {3, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u16(w, c.device.pump().analog_out_raw());
     },
     nullptr},
    {7, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 1); },
     nullptr},
    {8, Access::kGet, [](const RequestContext&, ByteWriter& w) noexcept { return put_u8(w, 0); },
     nullptr},
    {9, Access::kGetSet, get_aop_state<&AopSettings::fault_state>,
     set_aop_state<&AopSettings::fault_state>},
    {10, Access::kGetSet, get_aop_state<&AopSettings::idle_state>,
     set_aop_state<&AopSettings::idle_state>},
    {11, Access::kGetSet, get_aop_value<&AopSettings::fault_value>,
     set_aop_value<&AopSettings::fault_value>},
    {12, Access::kGetSet, get_aop_value<&AopSettings::idle_value>,
     set_aop_value<&AopSettings::idle_value>},
};

// ---------------------------------------------------------------------------
// Device Supervisor, class 0x32.

constexpr ClassAttributeDef kSupervisorClass[] = {{1, 1}, {2, 1}, {6, 7}, {7, 16}};

const AttributeDef kSupervisorAttributes[] = {
    {3, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept { return put_short_string(w, "ANALOG IO"); },
     nullptr},
    {4, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept { return put_short_string(w, "E00-0000"); },
     nullptr},
    {5, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept {
       return put_short_string(w, "D.I.P. Inc.");
     },
     nullptr},
    {6, Access::kGet,
     [](const RequestContext&, ByteWriter& w) noexcept { return put_short_string(w, "CDN127"); },
     nullptr},
    {7, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_revision_string(w, c.device.options().revision_major,
                                  c.device.options().revision_minor);
     },
     nullptr},
    {8, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_revision_string(w, c.device.options().hardware_major,
                                  c.device.options().hardware_minor);
     },
     nullptr},
    {11, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.supervisor_device_status());
     },
     nullptr},
    {12, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       c.device.pump().advance(c.now);
       return put_u8(w, c.device.exception_status_byte());
     },
     nullptr},
    {13, Access::kGet,  // nested exactly as the manual's table
     [](const RequestContext& c, ByteWriter& w) noexcept {
       w.u8(2);  // Common Detail: Size
       w.u8(0);
       w.u8(0);
       w.u8(8);  // Device Detail: Device Size
       w.u8(8);  // Number DIP
       w.u8(0);  // DIP Status (every DIP status attribute is 0)
       w.u8(8);  // Number DOP
       w.u8(c.device.faults().minor_recoverable ? 0x03 : 0x00);  // DOP Status
       w.u8(2);                                                  // Number AIP
       w.u8(0);                                                  // AIP Status
       w.u8(1);                                                  // Number AOP
       w.u8(0);                                                  // AOP Status
       w.u8(1);                                                  // Man. Detail Size
       w.u8(c.device.alarm_detail());
       return kReplyOk;
     },
     nullptr},
    {14, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       w.u8(2);  // Common Detail: Common Size
       w.u8(0);
       w.u8(0);
       w.u8(0);  // Device Detail: Device Size
       w.u8(1);  // Man. Detail: Man. Size
       w.u8(c.device.warning_detail());
       return kReplyOk;
     },
     nullptr},
    {15, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.e2().alarm_enable ? 1 : 0);
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       return read_bool(data, c.device.e2().alarm_enable);
     }},
    {16, Access::kGetSet,
     [](const RequestContext& c, ByteWriter& w) noexcept {
       return put_u8(w, c.device.e2().warning_enable ? 1 : 0);
     },
     [](const RequestContext& c, Bytes data, ByteWriter&) noexcept {
       return read_bool(data, c.device.e2().warning_enable);
     }},
};

// ---------------------------------------------------------------------------
// Configuration, class 0x40.

constexpr ClassAttributeDef kConfigurationClass[] = {{1, 1}, {2, 1}, {6, 7}, {7, 17}};

template <std::uint8_t IoConfiguration::*Field>
Reply get_config(const RequestContext& c, ByteWriter& w) noexcept {
  return put_u8(w, c.device.configuration().*Field);
}
template <std::uint8_t IoConfiguration::*Field>
Reply set_config(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  IoConfiguration next = c.device.configuration();
  Reply r = read_u8(data, next.*Field);
  return r.ok() ? c.device.set_configuration(next) : r;
}

Reply put_poll_size(const RequestContext& c, ByteWriter& w, bool produced) noexcept {
  auto format = profiles::cdn127::poll_format(c.device.configuration());
  if (!format.ok()) return put_u8(w, 0);
  return put_u8(w,
                static_cast<std::uint8_t>(produced ? format->response.size : format->request.size));
}

const AttributeDef kConfigurationAttributes[] = {
    {1, Access::kGetSet, get_config<&IoConfiguration::mode>, set_config<&IoConfiguration::mode>},
    {2, Access::kGetSet, get_config<&IoConfiguration::num_digital_inputs>,
     set_config<&IoConfiguration::num_digital_inputs>},
    {3, Access::kGetSet, get_config<&IoConfiguration::num_digital_outputs>,
     set_config<&IoConfiguration::num_digital_outputs>},
    {4, Access::kGetSet, get_config<&IoConfiguration::num_analog_inputs>,
     set_config<&IoConfiguration::num_analog_inputs>},
    {5, Access::kGetSet, get_config<&IoConfiguration::num_analog_outputs>,
     set_config<&IoConfiguration::num_analog_outputs>},
    {10, Access::kGetSet, get_config<&IoConfiguration::no_nc_mask>,
     set_config<&IoConfiguration::no_nc_mask>},
    {16, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return put_poll_size(c, w, true); },
     nullptr},
    {17, Access::kGet,
     [](const RequestContext& c, ByteWriter& w) noexcept { return put_poll_size(c, w, false); },
     nullptr},
};

// Reset: one byte, 0 = CDN127 preset, 1 = CDN118 preset.
Reply configuration_reset(const RequestContext& c, Bytes data, ByteWriter&) noexcept {
  Reply r = expect_size(data, 1);
  if (!r.ok()) return r;
  if (data[0] > 1) return reply_error(GeneralStatus::kInvalidParameter);
  return c.device.set_configuration(
      profiles::cdn127::preset(static_cast<profiles::cdn127::ConfigurationPreset>(data[0])));
}

// ---------------------------------------------------------------------------
// The class table. Columns: id, name, class attributes, instance attributes,
// Get (class), Get (instance), Set (instance), Reset (class), Reset
// (instance), Allocate, Release, instances.

const ClassDef kClasses[] = {
    {cls::kIdentity, cip::class_name(cls::kIdentity), kIdentityClass, kIdentityAttributes, true,
     true, false, nullptr, identity_reset, nullptr, nullptr, single_instance},
    {cls::kMessageRouter, cip::class_name(cls::kMessageRouter), kRouterClass, kRouterAttributes,
     true, true, false, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kDeviceNet, cip::class_name(cls::kDeviceNet), kDeviceNetClass, kDeviceNetAttributes, true,
     true, true, nullptr, nullptr, devicenet_allocate, devicenet_release, single_instance},
    {cls::kAssembly, cip::class_name(cls::kAssembly), kAssemblyClass, kAssemblyAttributes, true,
     true, true, nullptr, nullptr, nullptr, nullptr, assembly_exists},
    {cls::kConnection, cip::class_name(cls::kConnection), kConnectionClass, kConnectionAttributes,
     true, true, true, connection_class_reset, connection_reset, nullptr, nullptr,
     connection_exists},
    {cls::kDiscreteInputPoint, cip::class_name(cls::kDiscreteInputPoint), kDipClass, kDipAttributes,
     true, true, false, nullptr, nullptr, nullptr, nullptr, dip_exists},
    {cls::kDiscreteOutputPoint, cip::class_name(cls::kDiscreteOutputPoint), kDopClass,
     kDopAttributes, true, true, true, nullptr, nullptr, nullptr, nullptr, dop_exists},
    {cls::kAnalogInputPoint, cip::class_name(cls::kAnalogInputPoint), kAipClass, kAipAttributes,
     true, true, true, nullptr, nullptr, nullptr, nullptr, aip_exists},
    {cls::kAnalogOutputPoint, cip::class_name(cls::kAnalogOutputPoint), kAopClass, kAopAttributes,
     true, true, true, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kDeviceSupervisor, "Device Supervisor", kSupervisorClass, kSupervisorAttributes, true,
     true, true, nullptr, nullptr, nullptr, nullptr, single_instance},
    {cls::kConfiguration, "Configuration", kConfigurationClass, kConfigurationAttributes, true,
     true, true, nullptr, configuration_reset, nullptr, nullptr, single_instance},
};

// The attribute as this device's firmware has it: nullptr when the tables
// do not list it or the firmware lacks it (SlaveOptions::unsupported_attributes).
const AttributeDef* firmware_attribute(const Cdn127Device& device, const ClassDef& c,
                                       std::uint8_t attribute) noexcept {
  for (const ClassAttribute& missing : device.options().unsupported_attributes) {
    if (missing == ClassAttribute{c.id, attribute}) return nullptr;
  }
  return find_attribute(c, attribute);
}

// An attribute the manual lists Get/Set that this firmware has Get only
// (SlaveOptions::read_only_attributes).
bool firmware_read_only(const Cdn127Device& device, const ClassDef& c,
                        std::uint8_t attribute) noexcept {
  for (const ClassAttribute& fixed : device.options().read_only_attributes) {
    if (fixed == ClassAttribute{c.id, attribute}) return true;
  }
  return false;
}

Reply dispatch(Cdn127Device& device, const devicenet::RequestMessage& req, std::uint8_t requester,
               TimePoint now, ByteWriter& w) noexcept {
  const ClassDef* c = find_class(req.class_id);
  if (c == nullptr) return reply_error(GeneralStatus::kObjectDoesNotExist);
  const bool class_level = req.instance_id == 0;
  if (!class_level && !c->has_instance(device, req.instance_id)) {
    return reply_error(GeneralStatus::kObjectDoesNotExist);
  }
  const RequestContext ctx{device, req.instance_id, requester, now};
  const auto not_supported = reply_error(GeneralStatus::kServiceNotSupported);

  switch (static_cast<cip::Service>(req.service)) {
    case cip::Service::kGetAttributeSingle: {
      if (!(class_level ? c->class_get : c->instance_get)) return not_supported;
      if (!req.attribute) return reply_error(GeneralStatus::kNotEnoughData);
      if (!req.data.empty()) return reply_error(GeneralStatus::kTooMuchData);
      if (class_level) {
        for (const ClassAttributeDef& a : c->class_attributes) {
          if (a.id == *req.attribute) return put_u16(w, a.value);
        }
        return reply_error(GeneralStatus::kAttributeNotSupported);
      }
      const AttributeDef* a = firmware_attribute(device, *c, *req.attribute);
      if (a == nullptr) return reply_error(GeneralStatus::kAttributeNotSupported);
      return a->get(ctx, w);
    }
    case cip::Service::kSetAttributeSingle: {
      // No class lists Set at class level.
      if (class_level || !c->instance_set) return not_supported;
      if (!req.attribute) return reply_error(GeneralStatus::kNotEnoughData);
      const AttributeDef* a = firmware_attribute(device, *c, *req.attribute);
      if (a == nullptr) return reply_error(GeneralStatus::kAttributeNotSupported);
      if (a->access != Access::kGetSet || a->set == nullptr ||
          firmware_read_only(device, *c, *req.attribute)) {
        return reply_error(GeneralStatus::kAttributeNotSettable);
      }
      return a->set(ctx, req.data, w);
    }
    case cip::Service::kReset: {
      ServiceHandler h = class_level ? c->class_reset : c->instance_reset;
      return h != nullptr ? h(ctx, req.data, w) : not_supported;
    }
    case cip::Service::kAllocateMasterSlave:
      return (!class_level && c->allocate != nullptr) ? c->allocate(ctx, req.data, w)
                                                      : not_supported;
    case cip::Service::kReleaseMasterSlave:
      return (!class_level && c->release != nullptr) ? c->release(ctx, req.data, w) : not_supported;
    case cip::Service::kGetAttributesAll:
    case cip::Service::kSetAttributesAll:
    case cip::Service::kCreate:
    case cip::Service::kDelete:
    case cip::Service::kApplyAttributes:
    case cip::Service::kErrorResponse:
      break;
  }
  return not_supported;
}

}  // namespace

std::span<const ClassDef> object_classes() noexcept { return kClasses; }

const ClassDef* find_class(std::uint16_t class_id) noexcept {
  for (const ClassDef& c : kClasses) {
    if (c.id == class_id) return &c;
  }
  return nullptr;
}

const AttributeDef* find_attribute(const ClassDef& c, std::uint8_t attribute) noexcept {
  for (const AttributeDef& a : c.instance_attributes) {
    if (a.id == attribute) return &a;
  }
  return nullptr;
}

std::size_t execute_request(Cdn127Device& device, const devicenet::RequestMessage& request,
                            std::uint8_t requester, TimePoint now, MutableBytes out) noexcept {
  std::array<std::uint8_t, 64> data{};
  ByteWriter w(data);
  const Reply r = dispatch(device, request, requester, now, w);
  return encode_reply(request.service, r, w, out);
}

}  // namespace dnbridge::sim
