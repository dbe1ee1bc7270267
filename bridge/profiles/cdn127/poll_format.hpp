#pragma once
// The CDN127 poll request and response formats (manual, "Configuration
// Object" and "Poll Packet Sizes"):
//
//   Poll request:  [DOUT(0..1)] [PAD(0..1)] [AOUT(0..2)]
//   Poll response: [DSUP] [DIN(0..1)] [PAD(0..1)] [AIN(0..4)]
//
// computed from the Configuration object (Mode, Num Digital/Analog
// Input/Output), or fixed by the assembly instance the poll connection's
// paths name (produced: 1, 2, 3, 101, 102, 103; consumed: 5, 100, 104).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "bridge/common/bytes.hpp"
#include "bridge/common/result.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::profiles::cdn127 {

// Mode byte bits. The manual's bit table puts IncludeDSUP at bit 7,
// NoPollUpdate at bit 2 and NoEvenByte at bit 0, and says bits 3..5 "should
// be 0"; its presets 0x86 and 0x81 do not agree with it everywhere: see
// configuration.cpp for the reading taken.
namespace mode {
inline constexpr std::uint8_t kIncludeDsup = 0x80;
inline constexpr std::uint8_t kNoPollUpdate = 0x04;
inline constexpr std::uint8_t kNoEvenByte = 0x01;
}  // namespace mode

// The Configuration object's instance attributes that shape the poll messages.
struct IoConfiguration {
  std::uint8_t mode = 0x86;
  std::uint8_t num_digital_inputs = 8;   // 0..8
  std::uint8_t num_digital_outputs = 8;  // 0..8
  std::uint8_t num_analog_inputs = 2;    // 0..2
  std::uint8_t num_analog_outputs = 1;   // 0..1
  std::uint8_t no_nc_mask = 0;           // bit n: DIP instance n+1 reports 0 when active

  friend bool operator==(const IoConfiguration&, const IoConfiguration&) = default;
};

// The Reset service presets: 0 = CDN127 (full), 1 = CDN118.
IoConfiguration preset(ConfigurationPreset p) noexcept;

// Refuses counts over the device's maxima (8 DI, 8 DO, 2 AI, 1 AO) with kOutOfRange.
Status validate(const IoConfiguration& config) noexcept;

// Where each field sits in a poll message; a field absent has size 0 and the
// offset at which it would have started.
struct PollRequestLayout {
  std::size_t dout_offset = 0, dout_size = 0;
  std::size_t pad_size = 0;
  std::size_t aout_offset = 0, aout_count = 0;  // count of 2-byte words
  std::size_t size = 0;                         // the poll connection's consumed size

  // CDN127 manual, "Poll Packet Sizes": "If the Num Digital Output and Num
  // Analog Output are both 0 then the CONSUMED SIZE for the POLL connection
  // will be 0. In this case there is no POLL IDLE condition." Otherwise a
  // request shorter than `size` (a 0-byte poll, typically) makes the device idle.
  bool has_idle_condition() const noexcept { return size != 0; }

  friend bool operator==(const PollRequestLayout&, const PollRequestLayout&) = default;
};

struct PollResponseLayout {
  bool has_dsup = false;  // exception status byte first
  std::size_t din_offset = 0, din_size = 0;
  // How many input channels the input byte carries (Num Digital Input for the
  // configured format, 8 for the fixed assemblies): with fewer than 5 the byte
  // does not hold every pump input, and the higher bits mean nothing.
  std::size_t din_channels = 0;
  std::size_t pad_size = 0;
  std::size_t ain_offset = 0, ain_count = 0;  // count of 2-byte words
  std::size_t size = 0;                       // the poll connection's produced size

  friend bool operator==(const PollResponseLayout&, const PollResponseLayout&) = default;
};

struct PollFormat {
  PollRequestLayout request;
  PollResponseLayout response;

  friend bool operator==(const PollFormat&, const PollFormat&) = default;
};

// The formats the Configuration object selects (used through assemblies 103/104
// and by default). Fails on an invalid configuration.
Result<PollFormat> poll_format(const IoConfiguration& config) noexcept;

// The fixed formats of the produced assemblies 1, 2, 3, 101, 102 and the
// consumed assemblies 5, 100; 103 and 104 follow `config`. Fails with
// kOutOfRange for other instances or the wrong direction.
Result<PollResponseLayout> produced_assembly_layout(std::uint8_t instance,
                                                    const IoConfiguration& config) noexcept;
Result<PollRequestLayout> consumed_assembly_layout(std::uint8_t instance,
                                                   const IoConfiguration& config) noexcept;

// The CDN127 default: produced 103, consumed 104 (the formats the
// Configuration object defines).
inline constexpr std::uint8_t kDefaultProducedAssembly = 103;
inline constexpr std::uint8_t kDefaultConsumedAssembly = 104;

// Human-readable form for fault reasons, e.g. "request 4 B [DOUT PAD AOUT]",
// "response 6 B [DSUP DIN AIN AIN]", "request 0 B [] (no idle condition)".
// Allocates: for messages, not for the frame path.
std::string describe(const PollRequestLayout& layout);
std::string describe(const PollResponseLayout& layout);
std::string describe(const PollFormat& format);  // "<request>; <response>"

}  // namespace dnbridge::profiles::cdn127
