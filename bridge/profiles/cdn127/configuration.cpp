// The Configuration object (class 0x40) values that shape the poll messages:
// the Reset presets and the checks on a configuration.
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::profiles::cdn127 {

namespace {
// CDN127 manual, Configuration object, attributes 2..5: "The maximum number
// 8 bits" (digital), "The maximum number is 2" (analog inputs), "The maximum
// size is 1" (analog output).
constexpr std::uint8_t kMaxDigitalInputs = 8;
constexpr std::uint8_t kMaxDigitalOutputs = 8;
constexpr std::uint8_t kMaxAnalogInputs = 2;
constexpr std::uint8_t kMaxAnalogOutputs = 1;
}  // namespace

// CDN127 manual, "Configuration Reset Service": "0 Reset to provide full
// configuration", "1 Reset to match CDN118 configuration".
//
// The presets and the Mode bit table disagree. The table reads
//   Bit 7 IncludeDSUP | 6..3: 0 | Bit 2 NoPollUpdate | Bit 1: 0 | Bit 0 NoEvenByte
// with "Bits 3..5 should be set to 0", yet the CDN127 preset is "Mode 086H"
// (bit 1 set, which the table shows as 0). The reading taken: only bits 7, 2
// and 0 mean anything; every other bit is reserved and ignored, so 0x86 is
// IncludeDSUP + NoPollUpdate with padding on, which is what its description
// says ("Include DSUP in poll response. No I/O updated between poll request
// and poll response. Analog I/O maintained on even boundary.").
//
// The CDN118 preset is "Mode 81", described as "Forces Analog I/O data to even
// byte boundary", but 0x81 sets NoEvenByte ("If the NoEvenByte bit is set then
// no padding bytes will be inserted or expected"). The bit table is followed:
// 0x81 means no padding. With that preset's counts (no analog input, one
// digital output byte then the analog output) the two readings differ only in
// the request (3 B without a pad, 4 B with one); the master checks the sizes
// it computes against the device's Number Consumed / Number Produced
// (attributes 17/16) and the poll connection's sizes, so a device that reads
// its manual the other way is reported, not guessed at.
IoConfiguration preset(ConfigurationPreset p) noexcept {
  switch (p) {
    case ConfigurationPreset::kCdn118:
      return IoConfiguration{.mode = 0x81,
                             .num_digital_inputs = 8,
                             .num_digital_outputs = 8,
                             .num_analog_inputs = 0,
                             .num_analog_outputs = 1,
                             .no_nc_mask = 0};
    case ConfigurationPreset::kCdn127:
      break;
  }
  return IoConfiguration{.mode = 0x86,
                         .num_digital_inputs = 8,
                         .num_digital_outputs = 8,
                         .num_analog_inputs = 2,
                         .num_analog_outputs = 1,
                         .no_nc_mask = 0};
}

// The Mode byte is never refused: its reserved bits are ignored (see above).
// NoNcMask maps only DIP instances 1..5, but its other bits select nothing on
// the wire, so they are not refused either.
Status validate(const IoConfiguration& config) noexcept {
  if (config.num_digital_inputs > kMaxDigitalInputs ||
      config.num_digital_outputs > kMaxDigitalOutputs ||
      config.num_analog_inputs > kMaxAnalogInputs ||
      config.num_analog_outputs > kMaxAnalogOutputs) {
    return Errc::kOutOfRange;
  }
  return {};
}

}  // namespace dnbridge::profiles::cdn127
