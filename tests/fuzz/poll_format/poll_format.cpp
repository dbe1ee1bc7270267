// CDN127 poll formats and the poll message codecs over every layout the
// input selects. Input:
//   [selector]
//   [mode][num DI][num DO][num AI][num AO][NoNcMask]   the Configuration object
//   selector bit 0 clear: [produced assembly][consumed assembly]
//   selector bit 0 set:   raw layouts, one byte per field (response: has_dsup,
//                         din_offset, din_size, din_channels, pad_size,
//                         ain_offset, ain_count, size; request: dout_offset,
//                         dout_size, pad_size, aout_offset, aout_count, size)
//   [payload...]          decoded as a poll response and as a poll request
// Properties: the formats of a valid configuration are consistent; decoders
// refuse any payload but one of exactly the layout's size; what decodes
// re-encodes to a message that decodes to the same values, byte for byte
// except the pad byte (and reserved output bits).
#include "bridge/profiles/cdn127/poll_format.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

#include "bridge/profiles/cdn127/io_data.hpp"
#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::profiles::cdn127;

namespace {

bool same(const PollInputs& a, const PollInputs& b) {
  return a.exception_status == b.exception_status && a.input_bits == b.input_bits &&
         a.pump == b.pump && a.analog_inputs_raw == b.analog_inputs_raw &&
         a.analog_input_in_range == b.analog_input_in_range;
}

void check_response(const PollResponseLayout& layout, std::uint8_t mask, Bytes payload) {
  auto in = decode_poll_response(layout, mask, payload);
  if (!in) return;
  FUZZ_CHECK(payload.size() == layout.size);
  FUZZ_CHECK(in->exception_status.has_value() == layout.has_dsup);
  FUZZ_CHECK(in->input_bits.has_value() == (layout.din_size != 0));
  if (in->pump) FUZZ_CHECK(in->input_bits.has_value() && layout.din_channels >= 5);
  std::array<std::uint16_t, 2> analog{};
  bool in_range = true;
  for (std::size_t i = 0; i < 2; ++i) {
    FUZZ_CHECK(in->analog_inputs_raw[i].has_value() == (i < layout.ain_count));
    // A value off the 0..4095 scale is kept and marked, never dropped.
    if (in->analog_inputs_raw[i]) {
      FUZZ_CHECK(in->analog_input_in_range[i] == (*in->analog_inputs_raw[i] <= kAnalogMaxRaw));
      analog[i] = *in->analog_inputs_raw[i];
      in_range = in_range && in->analog_input_in_range[i];
    } else {
      FUZZ_CHECK(!in->analog_input_in_range[i]);
    }
  }
  FUZZ_CHECK(in->all_in_range() == in_range);
  // The encoder (the simulator's) writes only values on the scale.
  if (!in_range) return;
  const std::uint8_t dsup = layout.has_dsup ? payload[0] : 0;
  const std::uint8_t bits = in->input_bits.value_or(0);
  std::array<std::uint8_t, 16> buf{};
  auto n = encode_poll_response(layout, dsup, bits, analog, MutableBytes(buf));
  FUZZ_CHECK(n.ok() && *n == layout.size);
  for (std::size_t i = 0; i < *n; ++i) {
    const bool pad = layout.pad_size != 0 && i == layout.din_offset + layout.din_size;
    FUZZ_CHECK(pad ? buf[i] == 0 : buf[i] == payload[i]);
  }
  if (layout.size > 0) {
    FUZZ_CHECK(
        !encode_poll_response(layout, dsup, bits, analog, MutableBytes(buf.data(), layout.size - 1))
             .ok());
  }
  auto again = decode_poll_response(layout, mask, Bytes(buf.data(), *n));
  FUZZ_CHECK(again.ok() && same(*again, *in));
  if (in->exception_status)
    FUZZ_CHECK(ExceptionStatus::decode(in->exception_status->encode()) == *in->exception_status);
  if (in->pump) FUZZ_CHECK(PumpInputs::decode(in->pump->encode(mask), mask) == *in->pump);
}

void check_request(const PollRequestLayout& layout, Bytes payload) {
  auto out = decode_poll_request(layout, payload);
  if (!out) return;
  FUZZ_CHECK(payload.size() == layout.size);
  FUZZ_CHECK(validate(*out).ok());
  std::array<std::uint8_t, 16> buf{};
  auto n = encode_poll_request(layout, *out, MutableBytes(buf));
  FUZZ_CHECK(n.ok() && *n == layout.size);
  if (layout.dout_size != 0)
    FUZZ_CHECK(buf[0] == (payload[0] & (kOutputPumpOnBit | kOutputN2BallastBit)));
  if (layout.aout_count != 0) {
    FUZZ_CHECK(buf[layout.aout_offset] == payload[layout.aout_offset]);
    FUZZ_CHECK(buf[layout.aout_offset + 1] == payload[layout.aout_offset + 1]);
  }
  if (layout.size > 0)
    FUZZ_CHECK(!encode_poll_request(layout, *out, MutableBytes(buf.data(), layout.size - 1)).ok());
  auto again = decode_poll_request(layout, Bytes(buf.data(), *n));
  FUZZ_CHECK(again.ok() && *again == *out);
}

void check_format(const IoConfiguration& config, const PollFormat& f) {
  FUZZ_CHECK(f.request.size <= 4 && f.response.size <= 8);
  FUZZ_CHECK(f.request.has_idle_condition() ==
             (config.num_digital_outputs != 0 || config.num_analog_outputs != 0));
  FUZZ_CHECK(f.response.ain_count == config.num_analog_inputs);
  FUZZ_CHECK(f.request.aout_count == config.num_analog_outputs);
  // The Configuration-defined assemblies are the same formats.
  auto produced = produced_assembly_layout(kDefaultProducedAssembly, config);
  auto consumed = consumed_assembly_layout(kDefaultConsumedAssembly, config);
  FUZZ_CHECK(produced.ok() && *produced == f.response);
  FUZZ_CHECK(consumed.ok() && *consumed == f.request);
  FUZZ_CHECK(!describe(f).empty());
}

std::size_t field(ByteReader& r) { return r.u8(); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader r(Bytes(data, size));
  const std::uint8_t selector = r.u8();
  IoConfiguration config;
  config.mode = r.u8();
  config.num_digital_inputs = r.u8();
  config.num_digital_outputs = r.u8();
  config.num_analog_inputs = r.u8();
  config.num_analog_outputs = r.u8();
  config.no_nc_mask = r.u8();
  if (!r.ok()) return 0;

  auto format = poll_format(config);
  FUZZ_CHECK(format.ok() == validate(config).ok());
  if (format) check_format(config, *format);

  PollResponseLayout response;
  PollRequestLayout request;
  if ((selector & 1U) == 0) {
    const std::uint8_t produced = r.u8();
    const std::uint8_t consumed = r.u8();
    if (!r.ok()) return 0;
    if (auto p = produced_assembly_layout(produced, config)) response = *p;
    if (auto c = consumed_assembly_layout(consumed, config)) request = *c;
  } else {
    response.has_dsup = (r.u8() & 1U) != 0;
    response.din_offset = field(r);
    response.din_size = field(r);
    response.din_channels = field(r);
    response.pad_size = field(r);
    response.ain_offset = field(r);
    response.ain_count = field(r);
    response.size = field(r);
    request.dout_offset = field(r);
    request.dout_size = field(r);
    request.pad_size = field(r);
    request.aout_offset = field(r);
    request.aout_count = field(r);
    request.size = field(r);
    if (!r.ok()) return 0;
  }
  (void)describe(response);
  (void)describe(request);
  const Bytes payload = r.rest();
  check_response(response, config.no_nc_mask, payload);
  check_request(request, payload);
  return 0;
}
