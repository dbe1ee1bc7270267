#pragma once
// Decoded CDN127 process data: inputs with meaning, not bits; outputs checked
// before they are encoded.
#include <array>
#include <cstdint>
#include <optional>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::profiles::cdn127 {

inline constexpr std::uint16_t kAnalogMaxRaw = 4095;  // 0..4095 = 0..10 V
inline constexpr double kAnalogFullScaleVolts = 10.0;

double raw_to_volts(std::uint16_t raw) noexcept;
// Refuses values outside 0..10 V (kOutOfRange); rounds to the nearest step.
Result<std::uint16_t> volts_to_raw(double volts) noexcept;

// Device Supervisor exception status byte (manual, Assembly note (1) and
// Device Supervisor attribute 12).
struct ExceptionStatus {
  bool alarm_device_common = false;            // bit 0
  bool alarm_device_specific = false;          // bit 1: N2 flow, pump alarm or pump fail
  bool alarm_manufacturer_specific = false;    // bit 2
  bool warning_device_common = false;          // bit 4
  bool warning_device_specific = false;        // bit 5: pump warning
  bool warning_manufacturer_specific = false;  // bit 6
  bool expanded_mode = false;                  // bit 7

  static ExceptionStatus decode(std::uint8_t byte) noexcept;
  std::uint8_t encode() const noexcept;
  bool any_alarm() const noexcept;
  bool any_warning() const noexcept;
  friend bool operator==(const ExceptionStatus&, const ExceptionStatus&) = default;
};

// The pump's discrete inputs with their meaning. On the wire the device
// reports 1 for the NORMAL condition ("Pump Warning = 1 if NO warning"),
// unless the NoNcMask bit of that input is set, which inverts it.
struct PumpInputs {
  bool pump_running = false;    // poll bit 0, DIP 1
  bool warning_active = false;  // poll bit 1, DIP 2 (device: 1 = no warning)
  bool n2_flow_ok = false;      // poll bit 2, DIP 3
  bool alarm_active = false;    // poll bit 3, DIP 4 "Pump Fail"/"Pump Alarm" (device: 1 = no alarm)
  bool interlock_ok = false;    // poll bit 4, DIP 5

  // `bits` is the poll response's input byte, `no_nc_mask` the
  // Configuration object's attribute 10.
  static PumpInputs decode(std::uint8_t bits, std::uint8_t no_nc_mask) noexcept;
  // The inverse: the byte a device with this NoNcMask reports.
  std::uint8_t encode(std::uint8_t no_nc_mask) const noexcept;
  friend bool operator==(const PumpInputs&, const PumpInputs&) = default;
};

struct PollInputs {
  std::optional<ExceptionStatus> exception_status;  // when the format has DSUP
  std::optional<std::uint8_t> input_bits;           // raw input byte, when present
  // Decoded when the input byte carries all five pump inputs
  // (layout.din_channels >= 5): with fewer channels configured, the missing
  // inputs' bits would decode as alarms that are not there.
  std::optional<PumpInputs> pump;
  std::array<std::optional<std::uint16_t>, 2> analog_inputs_raw{};  // per channel, when present
  // Per channel: the value is on the 0..4095 scale. One above has no meaning
  // (a failed converter, a corrupted frame): kept as received, marked here.
  std::array<bool, 2> analog_input_in_range{};

  bool all_in_range() const noexcept {
    for (std::size_t i = 0; i < analog_inputs_raw.size(); ++i) {
      if (analog_inputs_raw[i] && !analog_input_in_range[i]) return false;
    }
    return true;
  }
};

// Decodes a poll response of exactly layout.size bytes (kTruncated if shorter,
// kMalformed if longer). An analog value over 4095 does not fail the response:
// it is kept and marked out of range (PollInputs::analog_input_in_range), and
// every other field stands. The pad byte's value is ignored. Every codec below refuses a layout
// whose fields do not add up to its size, or with more channels than the device has, with
// kOutOfRange.
Result<PollInputs> decode_poll_response(const PollResponseLayout& layout, std::uint8_t no_nc_mask,
                                        Bytes payload) noexcept;

// Pump outputs: poll request byte 0 bit 0 pump on, bit 2 N2 ballast on;
// analog output 0..4095.
struct PumpOutputs {
  bool pump_on = false;
  bool n2_ballast_on = false;
  std::uint16_t analog_out_raw = 0;

  friend bool operator==(const PumpOutputs&, const PumpOutputs&) = default;
};

inline constexpr std::uint8_t kOutputPumpOnBit = 0x01;
inline constexpr std::uint8_t kOutputN2BallastBit = 0x04;

// Refuses an analog value over 4095 (kOutOfRange): never clipped.
Status validate(const PumpOutputs& outputs) noexcept;

// Encodes a poll request into `out` (at least layout.size bytes, else
// kBufferTooSmall); returns the size written (layout.size). Pad bytes and the
// reserved output bits are 0; fields the layout does not carry are not sent.
Result<std::size_t> encode_poll_request(const PollRequestLayout& layout, const PumpOutputs& outputs,
                                        MutableBytes out) noexcept;
// The slave's side: decodes a full-size poll request (kTruncated if shorter:
// on the device a short request is the idle condition, the caller's to handle;
// kMalformed if longer; kOutOfRange for an analog value over 4095). Reserved
// output bits and pad bytes are ignored.
Result<PumpOutputs> decode_poll_request(const PollRequestLayout& layout, Bytes payload) noexcept;
// The slave's side: encodes a poll response (kOutOfRange for an analog value
// over 4095 in a channel the layout carries; kBufferTooSmall). Pad bytes are 0.
Result<std::size_t> encode_poll_response(const PollResponseLayout& layout,
                                         std::uint8_t exception_status, std::uint8_t input_bits,
                                         const std::array<std::uint16_t, 2>& analog_inputs_raw,
                                         MutableBytes out) noexcept;

}  // namespace dnbridge::profiles::cdn127
