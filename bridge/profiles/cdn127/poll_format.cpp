// The CDN127 poll request/response formats (manual, Configuration object
// "Mode Byte – Attribute 1", "Num ... – Attributes 2..5", "Poll Packet Sizes",
// and the Assembly object instances).
#include "bridge/profiles/cdn127/poll_format.hpp"

namespace dnbridge::profiles::cdn127 {

namespace {

// "Number of bytes = ((number of channels) + 7) / 8" (digital) and
// "Number of bytes = ((number of channels) * 2)" (analog).
constexpr std::size_t digital_bytes(std::uint8_t channels) noexcept {
  return (static_cast<std::size_t>(channels) + 7) / 8;
}

// Padding. The manual: "If this bit [NoEvenByte] is cleared then the POLL
// REQUEST and POLL RESPONSE packets will be adjusted to ensure that the Analog
// I/O data starts on an even byte boundary. Pad bytes will be eliminated in the
// Poll Request if the Num Analog Input is 0. Pad bytes will be eliminated in
// the Poll Response if the Num Analog Output is 0."
//
// The last two sentences read crossed: the request carries no analog input
// and the response no analog output, so a pad in the request could only ever
// align AOUT and one in the response only AIN. "Poll Packet Sizes" says so
// per message: the request PAD "is included to ensure that the AOUT are
// positioned on even byte boundaries", the response PAD "to ensure that the
// AIN are positioned on even byte boundaries". The reading taken: a pad
// aligns the analog data of its own message, so it exists iff NoEvenByte is
// clear, that message has analog data, and the analog data would otherwise
// start at an odd offset. This agrees with the fixed assemblies: 102 (input
// byte, pad, AIN[2]) and 104 (output byte, pad, AOUT) are padded, 101
// (exception byte, input byte, AIN[2]) needs no pad.
constexpr bool needs_pad(std::uint8_t mode_byte, std::size_t analog_words,
                         std::size_t analog_offset) noexcept {
  return (mode_byte & mode::kNoEvenByte) == 0 && analog_words != 0 && analog_offset % 2 != 0;
}

PollRequestLayout request_layout(std::size_t dout_size, std::size_t pad_size,
                                 std::size_t aout_count) noexcept {
  PollRequestLayout l;
  l.dout_offset = 0;
  l.dout_size = dout_size;
  l.pad_size = pad_size;
  l.aout_offset = dout_size + pad_size;
  l.aout_count = aout_count;
  l.size = l.aout_offset + 2 * aout_count;
  return l;
}

PollResponseLayout response_layout(bool has_dsup, std::size_t din_size, std::size_t din_channels,
                                   std::size_t pad_size, std::size_t ain_count) noexcept {
  PollResponseLayout l;
  l.has_dsup = has_dsup;
  l.din_offset = has_dsup ? 1 : 0;
  l.din_size = din_size;
  l.din_channels = din_channels;
  l.pad_size = pad_size;
  l.ain_offset = l.din_offset + din_size + pad_size;
  l.ain_count = ain_count;
  l.size = l.ain_offset + 2 * ain_count;
  return l;
}

// The fixed assemblies carry the whole input or output byte.
constexpr std::size_t kFixedChannels = 8;
constexpr std::size_t kFixedAnalogInputs = 2;

}  // namespace

Result<PollFormat> poll_format(const IoConfiguration& config) noexcept {
  if (Status s = validate(config); !s) return s.error();
  // Only IncludeDSUP (bit 7) and NoEvenByte (bit 0) shape the messages;
  // NoPollUpdate (bit 2) changes when the device samples, not the format.
  // The other bits are reserved and ignored (see configuration.cpp on 0x86).
  PollFormat f;

  // Poll request: [DOUT(0..1)] [PAD(0..1)] [AOUT(0..2)].
  const std::size_t dout = digital_bytes(config.num_digital_outputs);
  const std::size_t aout = config.num_analog_outputs;
  f.request = request_layout(dout, needs_pad(config.mode, aout, dout) ? 1 : 0, aout);

  // Poll response: [DSUP] [DIN(0..1)] [PAD(0..1)] [AIN(0..4)].
  const bool dsup = (config.mode & mode::kIncludeDsup) != 0;
  const std::size_t din = digital_bytes(config.num_digital_inputs);
  const std::size_t ain = config.num_analog_inputs;
  const std::size_t before_ain = (dsup ? 1 : 0) + din;
  f.response = response_layout(dsup, din, din != 0 ? config.num_digital_inputs : 0,
                               needs_pad(config.mode, ain, before_ain) ? 1 : 0, ain);
  return f;
}

// CDN127 manual, Assembly object: produced instances 1 (Exception Alarms), 2
// (Exception Alarms, Input States), 3 (Input States), 101 (Exception Alarms,
// Input States, Analog Inputs UINT[2]), 102 (Input States, Pad Byte, Analog
// Inputs UINT[2]); "Instance 103 uses the configuration defined by Class 64 to
// determine the format of the Produced packets" (its table's example layout is
// not used).
Result<PollResponseLayout> produced_assembly_layout(std::uint8_t instance,
                                                    const IoConfiguration& config) noexcept {
  switch (instance) {
    case 1:
      return response_layout(true, 0, 0, 0, 0);
    case 2:
      return response_layout(true, 1, kFixedChannels, 0, 0);
    case 3:
      return response_layout(false, 1, kFixedChannels, 0, 0);
    case 101:
      return response_layout(true, 1, kFixedChannels, 0, kFixedAnalogInputs);
    case 102:
      return response_layout(false, 1, kFixedChannels, 1, kFixedAnalogInputs);
    case 103: {
      Result<PollFormat> f = poll_format(config);
      if (!f) return f.error();
      return f->response;
    }
    default:
      return Errc::kOutOfRange;
  }
}

// Consumed instances 5 (Output States), 100 (Output States, Analog Output UINT,
// no pad); "Instance 104 uses the configuration defined by Class 64 to
// determine the format of the Consumed packets".
Result<PollRequestLayout> consumed_assembly_layout(std::uint8_t instance,
                                                   const IoConfiguration& config) noexcept {
  switch (instance) {
    case 5:
      return request_layout(1, 0, 0);
    case 100:
      return request_layout(1, 0, 1);
    case 104: {
      Result<PollFormat> f = poll_format(config);
      if (!f) return f.error();
      return f->request;
    }
    default:
      return Errc::kOutOfRange;
  }
}

namespace {
void append_field(std::string& s, const char* name, std::size_t times) {
  for (std::size_t i = 0; i < times; ++i) {
    if (s.back() != '[') s += ' ';
    s += name;
  }
}
}  // namespace

std::string describe(const PollRequestLayout& layout) {
  std::string s = "request " + std::to_string(layout.size) + " B [";
  append_field(s, "DOUT", layout.dout_size);
  append_field(s, "PAD", layout.pad_size);
  append_field(s, "AOUT", layout.aout_count);
  s += ']';
  if (!layout.has_idle_condition()) s += " (no idle condition)";
  return s;
}

std::string describe(const PollResponseLayout& layout) {
  std::string s = "response " + std::to_string(layout.size) + " B [";
  append_field(s, "DSUP", layout.has_dsup ? 1 : 0);
  append_field(s, "DIN", layout.din_size);
  append_field(s, "PAD", layout.pad_size);
  append_field(s, "AIN", layout.ain_count);
  s += ']';
  return s;
}

std::string describe(const PollFormat& format) {
  return describe(format.request) + "; " + describe(format.response);
}

}  // namespace dnbridge::profiles::cdn127
