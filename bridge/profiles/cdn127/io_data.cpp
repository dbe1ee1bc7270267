// CDN127 process data: the poll response's exception and input bytes with
// their meaning, analog scaling, and the poll request's outputs.
#include "bridge/profiles/cdn127/io_data.hpp"

#include <cmath>

namespace dnbridge::profiles::cdn127 {

// CDN127 manual, AIP "Value - Attribute 3": "integers in the range 0..4095
// corresponding to voltages in the range 0-10Vdc"; AOP: "000h (0) 0 volts,
// FFFh (4095) +10 volts". A raw value over 4095 scales past 10 V: callers get
// such values only from a source that did not validate them.
double raw_to_volts(std::uint16_t raw) noexcept {
  return static_cast<double>(raw) * kAnalogFullScaleVolts / static_cast<double>(kAnalogMaxRaw);
}

Result<std::uint16_t> volts_to_raw(double volts) noexcept {
  // Written so that NaN fails too.
  if (!(volts >= 0.0 && volts <= kAnalogFullScaleVolts)) return Errc::kOutOfRange;
  const double steps = volts * static_cast<double>(kAnalogMaxRaw) / kAnalogFullScaleVolts;
  return static_cast<std::uint16_t>(std::lround(steps));
}

namespace {
constexpr bool bit(std::uint8_t byte, int n) noexcept {
  return ((static_cast<unsigned>(byte) >> n) & 1U) != 0;
}
constexpr std::uint8_t set_if(bool on, int n) noexcept {
  return on ? static_cast<std::uint8_t>(1U << n) : std::uint8_t{0};
}
}  // namespace

// Device Supervisor "Exception Status – Attribute 12": 0 ALARM/Device Common,
// 1 ALARM/Device Specific, 2 ALARM/Manufacturer-specific, 3 "0", 4..6 the
// same three for WARNING, 7 "1 == Expanded Mode". Bit 3 is reserved and
// ignored. (The Assembly note (1) calls bit 7 "Reserved for future use"; the
// Device Supervisor table is the fuller definition.)
ExceptionStatus ExceptionStatus::decode(std::uint8_t byte) noexcept {
  ExceptionStatus s;
  s.alarm_device_common = bit(byte, 0);
  s.alarm_device_specific = bit(byte, 1);
  s.alarm_manufacturer_specific = bit(byte, 2);
  s.warning_device_common = bit(byte, 4);
  s.warning_device_specific = bit(byte, 5);
  s.warning_manufacturer_specific = bit(byte, 6);
  s.expanded_mode = bit(byte, 7);
  return s;
}

std::uint8_t ExceptionStatus::encode() const noexcept {
  return static_cast<std::uint8_t>(
      set_if(alarm_device_common, 0) | set_if(alarm_device_specific, 1) |
      set_if(alarm_manufacturer_specific, 2) | set_if(warning_device_common, 4) |
      set_if(warning_device_specific, 5) | set_if(warning_manufacturer_specific, 6) |
      set_if(expanded_mode, 7));
}

bool ExceptionStatus::any_alarm() const noexcept {
  return alarm_device_common || alarm_device_specific || alarm_manufacturer_specific;
}

bool ExceptionStatus::any_warning() const noexcept {
  return warning_device_common || warning_device_specific || warning_manufacturer_specific;
}

// Assembly note (1), "Discrete Inputs": bit 0 "Pump Running = 1 if pump is
// running", 1 "Pump Warning = 1 if NO warning condition", 2 "N2 flow = 1 if N2
// flow OKAY", 3 "Pump Alarm = 1 if NO alarm" (DIP instance 4, "Pump Fail"), 4
// "Pump Fail Interlock = 1 if interlock NOT failed".
// Configuration "NoNcMask – Attribute 10": "bit 0 maps to DIP Instance 1 etc.
// If the bit is clear the input is reported as a '1' when the input is
// active. If the NoNcMask bit is set the input is reported as a '0' when the
// input is active." DIP instance n+1 is poll bit n, so a set mask bit inverts
// that poll bit; XOR with the mask gives the polarity the table above states.
namespace {
constexpr std::uint8_t kPumpInputMask = 0x1F;  // the five pump inputs, bits 0..4
constexpr std::size_t kPumpInputChannels = 5;
}  // namespace

PumpInputs PumpInputs::decode(std::uint8_t bits, std::uint8_t no_nc_mask) noexcept {
  const auto normal = static_cast<std::uint8_t>(bits ^ no_nc_mask);
  PumpInputs p;
  p.pump_running = bit(normal, 0);
  p.warning_active = !bit(normal, 1);
  p.n2_flow_ok = bit(normal, 2);
  p.alarm_active = !bit(normal, 3);
  p.interlock_ok = bit(normal, 4);
  return p;
}

std::uint8_t PumpInputs::encode(std::uint8_t no_nc_mask) const noexcept {
  const auto normal = static_cast<std::uint8_t>(set_if(pump_running, 0) |
                                                set_if(!warning_active, 1) | set_if(n2_flow_ok, 2) |
                                                set_if(!alarm_active, 3) | set_if(interlock_ok, 4));
  return static_cast<std::uint8_t>((normal ^ no_nc_mask) & kPumpInputMask);
}

namespace {
// The layouts come from poll_format(); one whose fields do not add up, or that
// carries more channels than the device has (1 input byte, 2 analog inputs,
// 1 output byte, 1 analog output), is refused with kOutOfRange rather than read.
constexpr bool well_formed(const PollResponseLayout& l) noexcept {
  return l.din_offset == (l.has_dsup ? 1U : 0U) && l.din_size <= 1 && l.pad_size <= 1 &&
         l.ain_count <= 2 && l.ain_offset == l.din_offset + l.din_size + l.pad_size &&
         l.size == l.ain_offset + 2 * l.ain_count;
}
constexpr bool well_formed(const PollRequestLayout& l) noexcept {
  return l.dout_offset == 0 && l.dout_size <= 1 && l.pad_size <= 1 && l.aout_count <= 1 &&
         l.aout_offset == l.dout_size + l.pad_size && l.size == l.aout_offset + 2 * l.aout_count;
}
}  // namespace

Result<PollInputs> decode_poll_response(const PollResponseLayout& layout, std::uint8_t no_nc_mask,
                                        Bytes payload) noexcept {
  if (!well_formed(layout)) return Errc::kOutOfRange;
  if (payload.size() < layout.size) return Errc::kTruncated;
  if (payload.size() > layout.size) return Errc::kMalformed;
  ByteReader r{payload};
  PollInputs in;
  if (layout.has_dsup) in.exception_status = ExceptionStatus::decode(r.u8());
  if (layout.din_size != 0) {
    const std::uint8_t bits = r.u8();
    in.input_bits = bits;
    if (layout.din_channels >= kPumpInputChannels) in.pump = PumpInputs::decode(bits, no_nc_mask);
  }
  r.skip(layout.pad_size);  // the pad byte, whatever its value
  // A channel out of range fails that channel only: the discrete inputs and
  // the other channel of the same response are as good as ever, and dropping
  // them would freeze interlock and alarm states while the node looks fresh.
  for (std::size_t i = 0; i < layout.ain_count; ++i) {
    const std::uint16_t raw = r.u16le();
    in.analog_inputs_raw[i] = raw;
    in.analog_input_in_range[i] = raw <= kAnalogMaxRaw;
  }
  if (!r.ok() || !r.at_end()) return Errc::kMalformed;  // unreachable with a well-formed layout
  return in;
}

Status validate(const PumpOutputs& outputs) noexcept {
  if (outputs.analog_out_raw > kAnalogMaxRaw) return Errc::kOutOfRange;
  return {};
}

// Assembly note (2): "byte 0 ... Pump On/Off = 1 to turn pump on ... bit 2 N2
// Ballast On/Off = 1 to turn on Ballast", then "Analog output, ... lsb, ...
// msb" (after the pad in the padded formats).
Result<std::size_t> encode_poll_request(const PollRequestLayout& layout, const PumpOutputs& outputs,
                                        MutableBytes out) noexcept {
  if (!well_formed(layout)) return Errc::kOutOfRange;
  if (Status s = validate(outputs); !s) return s.error();
  if (out.size() < layout.size) return Errc::kBufferTooSmall;
  ByteWriter w{out};
  if (layout.dout_size != 0) {
    w.u8(static_cast<std::uint8_t>((outputs.pump_on ? kOutputPumpOnBit : 0) |
                                   (outputs.n2_ballast_on ? kOutputN2BallastBit : 0)));
  }
  if (layout.pad_size != 0) w.u8(0);
  if (layout.aout_count != 0) w.u16le(outputs.analog_out_raw);
  if (!w.ok() || w.size() != layout.size) return Errc::kBufferTooSmall;  // unreachable
  return w.size();
}

Result<PumpOutputs> decode_poll_request(const PollRequestLayout& layout, Bytes payload) noexcept {
  if (!well_formed(layout)) return Errc::kOutOfRange;
  if (payload.size() < layout.size) return Errc::kTruncated;
  if (payload.size() > layout.size) return Errc::kMalformed;
  ByteReader r{payload};
  PumpOutputs o;
  if (layout.dout_size != 0) {
    const std::uint8_t bits = r.u8();
    o.pump_on = (bits & kOutputPumpOnBit) != 0;
    o.n2_ballast_on = (bits & kOutputN2BallastBit) != 0;
  }
  r.skip(layout.pad_size);
  if (layout.aout_count != 0) {
    o.analog_out_raw = r.u16le();
    if (o.analog_out_raw > kAnalogMaxRaw) return Errc::kOutOfRange;
  }
  if (!r.ok() || !r.at_end()) return Errc::kMalformed;  // unreachable with a well-formed layout
  return o;
}

Result<std::size_t> encode_poll_response(const PollResponseLayout& layout,
                                         std::uint8_t exception_status, std::uint8_t input_bits,
                                         const std::array<std::uint16_t, 2>& analog_inputs_raw,
                                         MutableBytes out) noexcept {
  if (!well_formed(layout)) return Errc::kOutOfRange;
  for (std::size_t i = 0; i < layout.ain_count; ++i) {
    if (analog_inputs_raw[i] > kAnalogMaxRaw) return Errc::kOutOfRange;
  }
  if (out.size() < layout.size) return Errc::kBufferTooSmall;
  ByteWriter w{out};
  if (layout.has_dsup) w.u8(exception_status);
  if (layout.din_size != 0) w.u8(input_bits);
  if (layout.pad_size != 0) w.u8(0);
  for (std::size_t i = 0; i < layout.ain_count; ++i) w.u16le(analog_inputs_raw[i]);
  if (!w.ok() || w.size() != layout.size) return Errc::kBufferTooSmall;  // unreachable
  return w.size();
}

}  // namespace dnbridge::profiles::cdn127
