#include "bridge/profiles/cdn127/io_data.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "support/bytes.hpp"

namespace dnbridge::profiles::cdn127 {
namespace {

using test::ByteVec;
using test::hex;

IoConfiguration config(std::uint8_t mode_byte, std::uint8_t di, std::uint8_t dout, std::uint8_t ai,
                       std::uint8_t ao) {
  return IoConfiguration{.mode = mode_byte,
                         .num_digital_inputs = di,
                         .num_digital_outputs = dout,
                         .num_analog_inputs = ai,
                         .num_analog_outputs = ao,
                         .no_nc_mask = 0};
}

// Every layout a CDN127 can use: each valid configuration, and the fixed
// assemblies.
std::vector<PollFormat> every_format() {
  std::vector<PollFormat> out;
  for (unsigned m : {0x00U, 0x01U, 0x04U, 0x05U, 0x80U, 0x81U, 0x84U, 0x85U}) {
    const auto mode_byte = static_cast<std::uint8_t>(m);
    for (std::uint8_t di = 0; di <= 8; ++di) {
      for (std::uint8_t dout = 0; dout <= 8; ++dout) {
        for (std::uint8_t ai = 0; ai <= 2; ++ai) {
          for (std::uint8_t ao = 0; ao <= 1; ++ao) {
            out.push_back(poll_format(config(mode_byte, di, dout, ai, ao)).value());
          }
        }
      }
    }
  }
  const IoConfiguration c = preset(ConfigurationPreset::kCdn127);
  const std::uint8_t produced[] = {1, 2, 3, 101, 102};
  const std::uint8_t consumed[] = {5, 100, 5, 100, 100};
  for (std::size_t i = 0; i < 5; ++i) {
    out.push_back(PollFormat{consumed_assembly_layout(consumed[i], c).value(),
                             produced_assembly_layout(produced[i], c).value()});
  }
  return out;
}

// --- analog scaling ---------------------------------------------------------

TEST(Analog, RawScalesToZeroToTenVolts) {
  EXPECT_DOUBLE_EQ(raw_to_volts(0), 0.0);
  EXPECT_DOUBLE_EQ(raw_to_volts(4095), 10.0);
  EXPECT_NEAR(raw_to_volts(2048), 5.0012, 1e-4);
}

TEST(Analog, VoltsToRawRoundsToNearestStep) {
  EXPECT_EQ(volts_to_raw(0.0).value(), 0);
  EXPECT_EQ(volts_to_raw(10.0).value(), 4095);
  EXPECT_EQ(volts_to_raw(5.0).value(), 2048);  // 2047.5 steps
  EXPECT_EQ(volts_to_raw(0.0012).value(), 0);  // 0.49 step
  EXPECT_EQ(volts_to_raw(0.0013).value(), 1);  // 0.53 step
  for (unsigned raw = 0; raw <= kAnalogMaxRaw; ++raw) {
    const auto r = static_cast<std::uint16_t>(raw);
    ASSERT_EQ(volts_to_raw(raw_to_volts(r)).value(), r);
  }
}

TEST(Analog, VoltsOutsideTheRangeAreRefusedNotClipped) {
  for (double v :
       {-0.0001, -1.0, 10.0001, 11.0, std::numeric_limits<double>::quiet_NaN(),
        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    EXPECT_EQ(volts_to_raw(v).error(), Errc::kOutOfRange) << v;
  }
}

// --- exception status -------------------------------------------------------

TEST(ExceptionStatusTest, EachBitHasItsMeaning) {
  EXPECT_EQ(ExceptionStatus::decode(0x01), ExceptionStatus{.alarm_device_common = true});
  EXPECT_EQ(ExceptionStatus::decode(0x02), ExceptionStatus{.alarm_device_specific = true});
  EXPECT_EQ(ExceptionStatus::decode(0x04), ExceptionStatus{.alarm_manufacturer_specific = true});
  EXPECT_EQ(ExceptionStatus::decode(0x08), ExceptionStatus{});  // bit 3 reserved
  EXPECT_EQ(ExceptionStatus::decode(0x10), ExceptionStatus{.warning_device_common = true});
  EXPECT_EQ(ExceptionStatus::decode(0x20), ExceptionStatus{.warning_device_specific = true});
  EXPECT_EQ(ExceptionStatus::decode(0x40), ExceptionStatus{.warning_manufacturer_specific = true});
  EXPECT_EQ(ExceptionStatus::decode(0x80), ExceptionStatus{.expanded_mode = true});
}

TEST(ExceptionStatusTest, RoundTripsAndSummarises) {
  for (unsigned b = 0; b <= 0xFF; ++b) {
    const auto byte = static_cast<std::uint8_t>(b);
    const ExceptionStatus s = ExceptionStatus::decode(byte);
    EXPECT_EQ(s.encode(), byte & 0xF7) << b;  // all but reserved bit 3
    EXPECT_EQ(s.any_alarm(), (byte & 0x07) != 0) << b;
    EXPECT_EQ(s.any_warning(), (byte & 0x70) != 0) << b;
  }
}

// --- pump inputs and NoNcMask -----------------------------------------------

TEST(PumpInputsTest, HealthyRunningPumpWithDefaultPolarity) {
  // 0x1F: bit 0 running, 1 "1 if NO warning", 2 N2 flow OK, 3 "1 if NO
  // alarm", 4 interlock OK.
  const PumpInputs healthy{.pump_running = true,
                           .warning_active = false,
                           .n2_flow_ok = true,
                           .alarm_active = false,
                           .interlock_ok = true};
  EXPECT_EQ(PumpInputs::decode(0x1F, 0x00), healthy);
  EXPECT_EQ(healthy.encode(0x00), 0x1F);
  // Everything bad: stopped, warning, no N2, alarm, interlock failed.
  const PumpInputs bad{.pump_running = false,
                       .warning_active = true,
                       .n2_flow_ok = false,
                       .alarm_active = true,
                       .interlock_ok = false};
  EXPECT_EQ(PumpInputs::decode(0x00, 0x00), bad);
  // Reserved bits 5..7 mean nothing.
  EXPECT_EQ(PumpInputs::decode(0xFF, 0x00), healthy);
  EXPECT_EQ(PumpInputs::decode(0xE0, 0x00), bad);
}

struct PolarityGolden {
  int bit;
  std::uint8_t wire_mask_clear;  // wire byte for the "active" condition, NoNcMask bit clear
  std::uint8_t wire_mask_set;    // the same condition with the NoNcMask bit set
  PumpInputs expected;           // what both decode to (others healthy)
};

TEST(PumpInputsTest, NoNcMaskInvertsExactlyItsOwnBit) {
  const PumpInputs healthy{.pump_running = true,
                           .warning_active = false,
                           .n2_flow_ok = true,
                           .alarm_active = false,
                           .interlock_ok = true};
  auto with = [&](auto field, bool value) {
    PumpInputs p = healthy;
    p.*field = value;
    return p;
  };
  const PolarityGolden golden[] = {
      // bit 0 Pump Running: pump stopped is 0x1E (bit 0 clear); NoNcMask bit 0 set: 0x1F.
      {0, 0x1E, 0x1F, with(&PumpInputs::pump_running, false)},
      // bit 1 Pump Warning: a warning clears bit 1 (0x1D); inverted: 0x1F.
      {1, 0x1D, 0x1F, with(&PumpInputs::warning_active, true)},
      // bit 2 N2 flow: no flow clears bit 2 (0x1B); inverted: 0x1F.
      {2, 0x1B, 0x1F, with(&PumpInputs::n2_flow_ok, false)},
      // bit 3 Pump Alarm ("Pump Fail", DIP 4): an alarm clears bit 3 (0x17); inverted: 0x1F.
      {3, 0x17, 0x1F, with(&PumpInputs::alarm_active, true)},
      // bit 4 Pump Fail Interlock: failed clears bit 4 (0x0F); inverted: 0x1F.
      {4, 0x0F, 0x1F, with(&PumpInputs::interlock_ok, false)},
  };
  for (const auto& g : golden) {
    SCOPED_TRACE(g.bit);
    const auto mask = static_cast<std::uint8_t>(1U << g.bit);
    EXPECT_EQ(PumpInputs::decode(g.wire_mask_clear, 0), g.expected);
    EXPECT_EQ(PumpInputs::decode(g.wire_mask_set, mask), g.expected);
    EXPECT_EQ(g.expected.encode(0), g.wire_mask_clear);
    EXPECT_EQ(g.expected.encode(mask), g.wire_mask_set);
    // The mask bit of this input leaves the others alone: the healthy
    // condition reads 0x1F with bit `bit` cleared.
    EXPECT_EQ(healthy.encode(mask), static_cast<std::uint8_t>(0x1F & ~mask));
    EXPECT_EQ(PumpInputs::decode(static_cast<std::uint8_t>(0x1F & ~mask), mask), healthy);
  }
  // All five inverted: the healthy pump reports 0x00.
  EXPECT_EQ(healthy.encode(0x1F), 0x00);
  EXPECT_EQ(PumpInputs::decode(0x00, 0x1F), healthy);
}

TEST(PumpInputsTest, RoundTripsForEveryStateAndMask) {
  for (unsigned state = 0; state < 32; ++state) {
    const PumpInputs p{.pump_running = (state & 1) != 0,
                       .warning_active = (state & 2) != 0,
                       .n2_flow_ok = (state & 4) != 0,
                       .alarm_active = (state & 8) != 0,
                       .interlock_ok = (state & 16) != 0};
    for (unsigned m = 0; m <= 0xFF; ++m) {
      const auto mask = static_cast<std::uint8_t>(m);
      ASSERT_EQ(PumpInputs::decode(p.encode(mask), mask), p) << state << " " << m;
      ASSERT_EQ(p.encode(mask) & 0xE0, 0);
    }
  }
}

// --- poll response ----------------------------------------------------------

TEST(PollResponse, Cdn127PresetGolden) {
  const PollResponseLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  const ByteVec wire = {
      0x20,        // DSUP: warning device specific
      0x1D,        // DIN: running, bit 1 clear = warning, N2 OK, no alarm, interlock OK
      0xFF, 0x0F,  // AIN 0 = 4095 (LE)
      0x00, 0x08,  // AIN 1 = 2048 (LE)
  };
  const auto in = decode_poll_response(l, 0x00, wire);
  ASSERT_TRUE(in.ok());
  EXPECT_EQ(in->exception_status, ExceptionStatus{.warning_device_specific = true});
  EXPECT_EQ(in->input_bits, 0x1D);
  EXPECT_EQ(in->pump, (PumpInputs{.pump_running = true,
                                  .warning_active = true,
                                  .n2_flow_ok = true,
                                  .alarm_active = false,
                                  .interlock_ok = true}));
  EXPECT_EQ(in->analog_inputs_raw[0], 4095);
  EXPECT_EQ(in->analog_inputs_raw[1], 2048);

  std::array<std::uint8_t, 8> out{};
  EXPECT_EQ(encode_poll_response(l, 0x20, 0x1D, {4095, 2048}, out).value(), 6u);
  EXPECT_EQ(hex(Bytes(out.data(), 6)), hex(wire));
}

TEST(PollResponse, Assembly102GoldenIgnoresThePadValue) {
  const PollResponseLayout l =
      produced_assembly_layout(102, preset(ConfigurationPreset::kCdn127)).value();
  const ByteVec wire = {
      0x1F,        // DIN: healthy running pump
      0xA5,        // PAD: any value
      0x34, 0x02,  // AIN 0 = 0x234
      0x00, 0x00,  // AIN 1 = 0
  };
  const auto in = decode_poll_response(l, 0x00, wire);
  ASSERT_TRUE(in.ok());
  EXPECT_FALSE(in->exception_status.has_value());
  EXPECT_EQ(in->input_bits, 0x1F);
  EXPECT_EQ(in->analog_inputs_raw[0], 0x234);
  EXPECT_EQ(in->analog_inputs_raw[1], 0);
  std::array<std::uint8_t, 6> out{};
  ASSERT_TRUE(encode_poll_response(l, 0x00, 0x1F, {0x234, 0}, out).ok());
  EXPECT_EQ(hex(out), "1F 00 34 02 00 00");  // the encoder's pad is 0
}

TEST(PollResponse, NoNcMaskAppliesToThePollByte) {
  const PollResponseLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  // DSUP 0, DIN 0x00, AIN 0, 0: with every input inverted this is a healthy pump.
  const ByteVec wire = {0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_FALSE(decode_poll_response(l, 0x00, wire)->pump->pump_running);
  EXPECT_TRUE(decode_poll_response(l, 0x1F, wire)->pump->pump_running);
  EXPECT_FALSE(decode_poll_response(l, 0x1F, wire)->pump->alarm_active);
  EXPECT_EQ(decode_poll_response(l, 0x1F, wire)->input_bits, 0x00);  // raw stays raw
}

TEST(PollResponse, PumpIsDecodedOnlyWhenTheByteHoldsAllFiveInputs) {
  for (std::uint8_t di = 1; di <= 8; ++di) {
    const PollResponseLayout l = poll_format(config(0x00, di, 0, 0, 0))->response;
    const ByteVec wire = {0x07};
    const auto in = decode_poll_response(l, 0, wire);
    ASSERT_TRUE(in.ok());
    EXPECT_EQ(in->input_bits, 0x07);
    EXPECT_EQ(in->pump.has_value(), di >= 5) << int{di};
  }
}

// An analog value off the 0..4095 scale fails its channel only: it is kept
// and marked, and every other field of the response is decoded.
TEST(PollResponse, AnalogOverFullScaleIsMarkedAndTheRestDecoded) {
  const PollResponseLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  // [00 DSUP][1F inputs: all normal][00 AIN1 4096 = 00 10][AIN2 0]
  const ByteVec wire = {0x00, 0x1F, 0x00, 0x10, 0x00, 0x00};
  const auto in = decode_poll_response(l, 0, wire);
  ASSERT_TRUE(in.ok());
  EXPECT_EQ(in->analog_inputs_raw[0], 4096);
  EXPECT_FALSE(in->analog_input_in_range[0]);
  EXPECT_EQ(in->analog_inputs_raw[1], 0);
  EXPECT_TRUE(in->analog_input_in_range[1]);
  EXPECT_FALSE(in->all_in_range());
  ASSERT_TRUE(in->pump.has_value());
  EXPECT_TRUE(in->pump->interlock_ok);
  EXPECT_FALSE(in->pump->alarm_active);
  // [DSUP][00 inputs: pump alarm, interlock open, no N2][AIN1 0][AIN2 65535 = FF FF]
  const ByteVec wire2 = {0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF};
  const auto in2 = decode_poll_response(l, 0, wire2);
  ASSERT_TRUE(in2.ok());
  EXPECT_EQ(in2->analog_inputs_raw[1], 65535);
  EXPECT_FALSE(in2->analog_input_in_range[1]);
  EXPECT_TRUE(in2->analog_input_in_range[0]);
  EXPECT_TRUE(in2->pump->alarm_active);
  EXPECT_FALSE(in2->pump->interlock_ok);
  const ByteVec good = {0x00, 0x1F, 0xFF, 0x0F, 0x00, 0x00};  // AIN1 4095: the top of the scale
  EXPECT_TRUE(decode_poll_response(l, 0, good)->all_in_range());
  std::array<std::uint8_t, 6> out{};
  EXPECT_EQ(encode_poll_response(l, 0, 0, {4096, 0}, out).error(), Errc::kOutOfRange);
  EXPECT_EQ(encode_poll_response(l, 0, 0, {0, 4096}, out).error(), Errc::kOutOfRange);
  // A channel the layout does not carry is not checked.
  const PollResponseLayout one = poll_format(config(0x80, 8, 0, 1, 0))->response;
  EXPECT_TRUE(encode_poll_response(one, 0, 0, {0, 65535}, out).ok());
}

TEST(PollResponse, RoundTripsTruncationAndOverlengthForEveryLayout) {
  std::mt19937 rng(127);
  std::uniform_int_distribution<unsigned> byte(0, 255), analog(0, kAnalogMaxRaw);
  int layouts = 0;
  for (const PollFormat& f : every_format()) {
    const PollResponseLayout& l = f.response;
    SCOPED_TRACE(describe(l));
    for (int trial = 0; trial < 4; ++trial) {
      const auto dsup = static_cast<std::uint8_t>(byte(rng));
      const auto din = static_cast<std::uint8_t>(byte(rng));
      const auto mask = static_cast<std::uint8_t>(byte(rng));
      const std::array<std::uint16_t, 2> ain = {static_cast<std::uint16_t>(analog(rng)),
                                                static_cast<std::uint16_t>(analog(rng))};
      std::array<std::uint8_t, 16> buf{};
      buf.fill(0xEE);
      const auto n = encode_poll_response(l, dsup, din, ain, buf);
      ASSERT_TRUE(n.ok());
      ASSERT_EQ(*n, l.size);
      EXPECT_EQ(buf[l.size], 0xEE);  // nothing written past the message
      if (l.pad_size) {
        EXPECT_EQ(buf[l.ain_offset - 1], 0x00);
      }
      const Bytes wire(buf.data(), l.size);

      const auto in = decode_poll_response(l, mask, wire);
      ASSERT_TRUE(in.ok());
      EXPECT_EQ(in->exception_status.has_value(), l.has_dsup);
      if (l.has_dsup) {
        EXPECT_EQ(*in->exception_status, ExceptionStatus::decode(dsup));
      }
      EXPECT_EQ(in->input_bits.has_value(), l.din_size == 1);
      if (l.din_size) {
        EXPECT_EQ(*in->input_bits, din);
      }
      if (in->pump) {
        EXPECT_EQ(*in->pump, PumpInputs::decode(din, mask));
      }
      for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(in->analog_inputs_raw[i].has_value(), i < l.ain_count);
        if (i < l.ain_count) {
          EXPECT_EQ(*in->analog_inputs_raw[i], ain[i]);
        }
      }
      for (std::size_t k = 0; k < l.size; ++k) {
        ASSERT_EQ(decode_poll_response(l, mask, wire.first(k)).error(), Errc::kTruncated) << k;
      }
      ByteVec longer(wire.begin(), wire.end());
      longer.push_back(0);
      EXPECT_EQ(decode_poll_response(l, mask, longer).error(), Errc::kMalformed);
      if (l.size) {
        EXPECT_EQ(
            encode_poll_response(l, dsup, din, ain, MutableBytes(buf.data(), l.size - 1)).error(),
            Errc::kBufferTooSmall);
      }
    }
    ++layouts;
  }
  EXPECT_EQ(layouts, 8 * 9 * 9 * 3 * 2 + 5);
}

TEST(PollResponse, GarbageOfAnyLengthNeverDecodesWrongly) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<unsigned> byte(0, 255), len(0, 10);
  const PollResponseLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  for (int i = 0; i < 2000; ++i) {
    ByteVec g(len(rng));
    for (auto& b : g) b = static_cast<std::uint8_t>(byte(rng));
    const auto in = decode_poll_response(l, 0, g);
    if (g.size() != 6) {
      EXPECT_FALSE(in.ok());
    } else {
      // Any six bytes decode; a channel off the scale is marked, not taken as valid.
      ASSERT_TRUE(in.ok());
      EXPECT_EQ(in->analog_input_in_range[0], (g[2] | (g[3] << 8)) <= 4095);
      EXPECT_EQ(in->analog_input_in_range[1], (g[4] | (g[5] << 8)) <= 4095);
    }
  }
}

TEST(PollResponse, InconsistentLayoutsAreRefused) {
  PollResponseLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  l.size = 7;
  const ByteVec seven(7, 0);
  std::array<std::uint8_t, 8> out{};
  EXPECT_EQ(decode_poll_response(l, 0, seven).error(), Errc::kOutOfRange);
  EXPECT_EQ(encode_poll_response(l, 0, 0, {0, 0}, out).error(), Errc::kOutOfRange);
  PollResponseLayout three = poll_format(preset(ConfigurationPreset::kCdn127))->response;
  three.ain_count = 3;
  three.size = 8;
  EXPECT_EQ(decode_poll_response(three, 0, ByteVec(8, 0)).error(), Errc::kOutOfRange);
}

// --- poll request -----------------------------------------------------------

TEST(PollRequest, Cdn127PresetGolden) {
  const PollRequestLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->request;
  const PumpOutputs o{.pump_on = true, .n2_ballast_on = true, .analog_out_raw = 0x0ABC};
  std::array<std::uint8_t, 4> out{};
  ASSERT_EQ(encode_poll_request(l, o, out).value(), 4u);
  // DOUT: bit 0 pump on, bit 2 N2 ballast; PAD 0; AOUT 0x0ABC (LE).
  EXPECT_EQ(hex(out), "05 00 BC 0A");
  EXPECT_EQ(decode_poll_request(l, out).value(), o);
}

TEST(PollRequest, Cdn118AndAssembly100Golden) {
  const PumpOutputs o{.pump_on = true, .n2_ballast_on = false, .analog_out_raw = 4095};
  std::array<std::uint8_t, 3> out{};
  const PollRequestLayout cdn118 = poll_format(preset(ConfigurationPreset::kCdn118))->request;
  ASSERT_EQ(encode_poll_request(cdn118, o, out).value(), 3u);
  EXPECT_EQ(hex(out), "01 FF 0F");  // DOUT pump on; AOUT 4095, no pad
  const PollRequestLayout a100 =
      consumed_assembly_layout(100, preset(ConfigurationPreset::kCdn127)).value();
  ASSERT_EQ(encode_poll_request(a100, o, out).value(), 3u);
  EXPECT_EQ(hex(out), "01 FF 0F");
  const PollRequestLayout a5 =
      consumed_assembly_layout(5, preset(ConfigurationPreset::kCdn127)).value();
  ASSERT_EQ(encode_poll_request(a5, {.n2_ballast_on = true}, out).value(), 1u);
  EXPECT_EQ(out[0], 0x04);  // N2 ballast only
}

TEST(PollRequest, ReservedBitsAndPadAreIgnoredByTheDecoder) {
  const PollRequestLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->request;
  const ByteVec wire = {0xFA, 0x77, 0x00, 0x00};  // bit 0 clear, bit 2 clear: all off
  EXPECT_EQ(decode_poll_request(l, wire).value(), PumpOutputs{});
}

TEST(PollRequest, AnalogOverFullScaleIsRefusedNeverClipped) {
  const PollRequestLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->request;
  std::array<std::uint8_t, 4> out = {0xEE, 0xEE, 0xEE, 0xEE};
  for (std::uint16_t bad : {std::uint16_t{4096}, std::uint16_t{0xFFFF}}) {
    const PumpOutputs o{.pump_on = true, .analog_out_raw = bad};
    EXPECT_EQ(validate(o).error(), Errc::kOutOfRange);
    EXPECT_EQ(encode_poll_request(l, o, out).error(), Errc::kOutOfRange);
    EXPECT_EQ(hex(out), "EE EE EE EE");  // nothing written
  }
  EXPECT_TRUE(validate(PumpOutputs{.analog_out_raw = 4095}).ok());
  const ByteVec wire = {0x01, 0x00, 0x00, 0x10};  // AOUT 4096
  EXPECT_EQ(decode_poll_request(l, wire).error(), Errc::kOutOfRange);
}

TEST(PollRequest, NoOutputsMeansAnEmptyRequest) {
  const PollRequestLayout l = poll_format(config(0x86, 8, 0, 2, 0))->request;
  std::array<std::uint8_t, 1> out = {0xEE};
  EXPECT_EQ(encode_poll_request(l, {.pump_on = true}, out).value(), 0u);
  EXPECT_EQ(out[0], 0xEE);
  EXPECT_EQ(decode_poll_request(l, Bytes{}).value(), PumpOutputs{});
  EXPECT_EQ(decode_poll_request(l, out).error(), Errc::kMalformed);
}

TEST(PollRequest, RoundTripsTruncationAndOverlengthForEveryLayout) {
  std::mt19937 rng(118);
  std::uniform_int_distribution<unsigned> bit(0, 1), analog(0, kAnalogMaxRaw);
  for (const PollFormat& f : every_format()) {
    const PollRequestLayout& l = f.request;
    SCOPED_TRACE(describe(l));
    for (int trial = 0; trial < 4; ++trial) {
      const PumpOutputs o{.pump_on = bit(rng) != 0,
                          .n2_ballast_on = bit(rng) != 0,
                          .analog_out_raw = static_cast<std::uint16_t>(analog(rng))};
      std::array<std::uint8_t, 8> buf{};
      buf.fill(0xEE);
      ASSERT_EQ(encode_poll_request(l, o, buf).value(), l.size);
      EXPECT_EQ(buf[l.size], 0xEE);
      if (l.pad_size) {
        EXPECT_EQ(buf[l.aout_offset - 1], 0x00);
      }
      if (l.dout_size) {
        EXPECT_EQ(buf[0] & ~0x05, 0);  // reserved output bits 0
      }
      const Bytes wire(buf.data(), l.size);
      const auto back = decode_poll_request(l, wire);
      ASSERT_TRUE(back.ok());
      const PumpOutputs expected{
          .pump_on = l.dout_size ? o.pump_on : false,
          .n2_ballast_on = l.dout_size ? o.n2_ballast_on : false,
          .analog_out_raw = l.aout_count ? o.analog_out_raw : std::uint16_t{0}};
      EXPECT_EQ(*back, expected);
      for (std::size_t k = 0; k < l.size; ++k) {
        ASSERT_EQ(decode_poll_request(l, wire.first(k)).error(), Errc::kTruncated) << k;
      }
      ByteVec longer(wire.begin(), wire.end());
      longer.push_back(0);
      EXPECT_EQ(decode_poll_request(l, longer).error(), Errc::kMalformed);
      if (l.size) {
        EXPECT_EQ(encode_poll_request(l, o, MutableBytes(buf.data(), l.size - 1)).error(),
                  Errc::kBufferTooSmall);
      }
    }
  }
}

TEST(PollRequest, InconsistentLayoutsAreRefused) {
  PollRequestLayout l = poll_format(preset(ConfigurationPreset::kCdn127))->request;
  l.aout_offset = 1;  // pad counted but AOUT placed over it
  std::array<std::uint8_t, 4> out{};
  EXPECT_EQ(encode_poll_request(l, {}, out).error(), Errc::kOutOfRange);
  EXPECT_EQ(decode_poll_request(l, out).error(), Errc::kOutOfRange);
}

}  // namespace
}  // namespace dnbridge::profiles::cdn127
