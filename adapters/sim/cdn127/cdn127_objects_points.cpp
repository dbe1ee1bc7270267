// The CDN127's I/O points: Discrete Input Point, Discrete Output Point,
// Analog Input Point and Analog Output Point (classes 0x08 to 0x0B).
#include "adapters/sim/cdn127/cdn127_objects_internal.hpp"
#include "adapters/sim/generic/attribute_codec.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim::cdn127_objects_detail {

using cip::GeneralStatus;
using profiles::cdn127::PumpOutputs;

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

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace dnbridge::sim::cdn127_objects_detail
