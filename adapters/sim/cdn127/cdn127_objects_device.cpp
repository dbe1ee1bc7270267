// The CDN127's own view of itself: Device Supervisor (class 0x32), its
// identity strings, status and alarm and warning details, and Configuration
// (class 0x40), the I/O configuration and the poll sizes it gives.
#include <array>
#include <string_view>

#include "adapters/sim/cdn127/cdn127_objects_internal.hpp"
#include "adapters/sim/generic/attribute_codec.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim::cdn127_objects_detail {

using cip::GeneralStatus;
using profiles::cdn127::IoConfiguration;

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace dnbridge::sim::cdn127_objects_detail
