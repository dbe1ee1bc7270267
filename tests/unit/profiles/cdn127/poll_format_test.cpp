#include "bridge/profiles/cdn127/poll_format.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace dnbridge::profiles::cdn127 {
namespace {

IoConfiguration config(std::uint8_t mode_byte, std::uint8_t di, std::uint8_t dout, std::uint8_t ai,
                       std::uint8_t ao) {
  return IoConfiguration{.mode = mode_byte,
                         .num_digital_inputs = di,
                         .num_digital_outputs = dout,
                         .num_analog_inputs = ai,
                         .num_analog_outputs = ao,
                         .no_nc_mask = 0};
}

// An independent model of "Poll Packet Sizes": lay the message out byte by
// byte as a list of field names, padding before the analog data when it would
// start at an odd index, and read sizes and offsets off that list.
struct Model {
  std::vector<std::string> bytes;
  std::size_t count(const std::string& f) const {
    std::size_t n = 0;
    for (const auto& b : bytes) n += (b == f);
    return n;
  }
  std::size_t first(const std::string& f) const {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (bytes[i] == f) return i;
    }
    return bytes.size();  // absent: where it would have started is checked separately
  }
};

Model model_request(std::uint8_t mode_byte, unsigned dout, unsigned ao) {
  Model m;
  if (dout > 0) m.bytes.push_back("DOUT");
  if (!(mode_byte & 0x01) && ao > 0 && m.bytes.size() % 2 == 1) m.bytes.push_back("PAD");
  for (unsigned i = 0; i < ao; ++i) m.bytes.insert(m.bytes.end(), {"AOUT", "AOUT"});
  return m;
}

Model model_response(std::uint8_t mode_byte, unsigned di, unsigned ai) {
  Model m;
  if (mode_byte & 0x80) m.bytes.push_back("DSUP");
  if (di > 0) m.bytes.push_back("DIN");
  if (!(mode_byte & 0x01) && ai > 0 && m.bytes.size() % 2 == 1) m.bytes.push_back("PAD");
  for (unsigned i = 0; i < ai; ++i) m.bytes.insert(m.bytes.end(), {"AIN", "AIN"});
  return m;
}

TEST(PollFormat, EveryValidConfigurationMatchesTheModel) {
  int checked = 0;
  // Mode bits 7, 2 and 0 in every combination; reserved bits added to half of
  // them must change nothing.
  for (unsigned bits = 0; bits < 8; ++bits) {
    for (std::uint8_t reserved : {std::uint8_t{0x00}, std::uint8_t{0x7A}}) {
      const auto mode_byte = static_cast<std::uint8_t>(
          ((bits & 4) ? 0x80 : 0) | ((bits & 2) ? 0x04 : 0) | ((bits & 1) ? 0x01 : 0) | reserved);
      for (std::uint8_t di = 0; di <= 8; ++di) {
        for (std::uint8_t dout = 0; dout <= 8; ++dout) {
          for (std::uint8_t ai = 0; ai <= 2; ++ai) {
            for (std::uint8_t ao = 0; ao <= 1; ++ao) {
              SCOPED_TRACE(testing::Message()
                           << "mode " << int{mode_byte} << " DI " << int{di} << " DO " << int{dout}
                           << " AI " << int{ai} << " AO " << int{ao});
              const IoConfiguration c = config(mode_byte, di, dout, ai, ao);
              ASSERT_TRUE(validate(c).ok());
              const Result<PollFormat> f = poll_format(c);
              ASSERT_TRUE(f.ok());

              const Model rq = model_request(mode_byte, dout, ao);
              EXPECT_EQ(f->request.size, rq.bytes.size());
              EXPECT_EQ(f->request.dout_offset, 0u);
              EXPECT_EQ(f->request.dout_size, rq.count("DOUT"));
              EXPECT_EQ(f->request.pad_size, rq.count("PAD"));
              EXPECT_EQ(f->request.aout_count * 2, rq.count("AOUT"));
              EXPECT_EQ(f->request.aout_offset, ao ? rq.first("AOUT") : rq.bytes.size());
              EXPECT_EQ(f->request.has_idle_condition(), dout > 0 || ao > 0);

              const Model rs = model_response(mode_byte, di, ai);
              EXPECT_EQ(f->response.size, rs.bytes.size());
              EXPECT_EQ(f->response.has_dsup, rs.count("DSUP") == 1);
              EXPECT_EQ(f->response.din_size, rs.count("DIN"));
              EXPECT_EQ(f->response.din_offset, rs.count("DSUP"));
              EXPECT_EQ(f->response.din_channels, di);
              EXPECT_EQ(f->response.pad_size, rs.count("PAD"));
              EXPECT_EQ(f->response.ain_count * 2, rs.count("AIN"));
              EXPECT_EQ(f->response.ain_offset, ai ? rs.first("AIN") : rs.bytes.size());
              // With NoEvenByte clear, analog data always starts even.
              if (!(mode_byte & 0x01)) {
                if (ao) {
                  EXPECT_EQ(f->request.aout_offset % 2, 0u);
                }
                if (ai) {
                  EXPECT_EQ(f->response.ain_offset % 2, 0u);
                }
              }

              // The assemblies that follow the Configuration object agree.
              EXPECT_EQ(produced_assembly_layout(103, c).value(), f->response);
              EXPECT_EQ(consumed_assembly_layout(104, c).value(), f->request);
              ++checked;
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(checked, 8 * 2 * 9 * 9 * 3 * 2);
}

TEST(PollFormat, Cdn127PresetIsFourByteRequestSixByteResponse) {
  const IoConfiguration c = preset(ConfigurationPreset::kCdn127);
  EXPECT_EQ(c, config(0x86, 8, 8, 2, 1));
  const PollFormat f = poll_format(c).value();
  // Request: byte 0 DOUT, byte 1 PAD, bytes 2-3 AOUT.
  EXPECT_EQ(f.request, (PollRequestLayout{.dout_offset = 0,
                                          .dout_size = 1,
                                          .pad_size = 1,
                                          .aout_offset = 2,
                                          .aout_count = 1,
                                          .size = 4}));
  // Response: byte 0 DSUP, byte 1 DIN, bytes 2-5 AIN[2]; DSUP+DIN is even: no pad.
  EXPECT_EQ(f.response, (PollResponseLayout{.has_dsup = true,
                                            .din_offset = 1,
                                            .din_size = 1,
                                            .din_channels = 8,
                                            .pad_size = 0,
                                            .ain_offset = 2,
                                            .ain_count = 2,
                                            .size = 6}));
  EXPECT_EQ(describe(f), "request 4 B [DOUT PAD AOUT]; response 6 B [DSUP DIN AIN AIN]");
}

TEST(PollFormat, Cdn118PresetFollowsNoEvenByte) {
  const IoConfiguration c = preset(ConfigurationPreset::kCdn118);
  EXPECT_EQ(c, config(0x81, 8, 8, 0, 1));
  const PollFormat f = poll_format(c).value();
  // Request: byte 0 DOUT, bytes 1-2 AOUT (NoEvenByte set: no pad).
  EXPECT_EQ(f.request, (PollRequestLayout{.dout_offset = 0,
                                          .dout_size = 1,
                                          .pad_size = 0,
                                          .aout_offset = 1,
                                          .aout_count = 1,
                                          .size = 3}));
  // Response: byte 0 DSUP, byte 1 DIN.
  EXPECT_EQ(f.response, (PollResponseLayout{.has_dsup = true,
                                            .din_offset = 1,
                                            .din_size = 1,
                                            .din_channels = 8,
                                            .pad_size = 0,
                                            .ain_offset = 2,
                                            .ain_count = 0,
                                            .size = 2}));
  EXPECT_EQ(describe(f), "request 3 B [DOUT AOUT]; response 2 B [DSUP DIN]");
}

struct ProducedGolden {
  std::uint8_t instance;
  PollResponseLayout layout;
  const char* text;
};

TEST(PollFormat, FixedProducedAssemblies) {
  // Any configuration, even an invalid one, leaves the fixed assemblies alone.
  const IoConfiguration odd = config(0x01, 0, 0, 0, 0);
  const IoConfiguration bad = config(0x00, 9, 9, 3, 2);
  const ProducedGolden golden[] = {
      {1,
       {.has_dsup = true,
        .din_offset = 1,
        .din_size = 0,
        .din_channels = 0,
        .pad_size = 0,
        .ain_offset = 1,
        .ain_count = 0,
        .size = 1},
       "response 1 B [DSUP]"},
      {2,
       {.has_dsup = true,
        .din_offset = 1,
        .din_size = 1,
        .din_channels = 8,
        .pad_size = 0,
        .ain_offset = 2,
        .ain_count = 0,
        .size = 2},
       "response 2 B [DSUP DIN]"},
      {3,
       {.has_dsup = false,
        .din_offset = 0,
        .din_size = 1,
        .din_channels = 8,
        .pad_size = 0,
        .ain_offset = 1,
        .ain_count = 0,
        .size = 1},
       "response 1 B [DIN]"},
      {101,
       {.has_dsup = true,
        .din_offset = 1,
        .din_size = 1,
        .din_channels = 8,
        .pad_size = 0,
        .ain_offset = 2,
        .ain_count = 2,
        .size = 6},
       "response 6 B [DSUP DIN AIN AIN]"},
      {102,
       {.has_dsup = false,
        .din_offset = 0,
        .din_size = 1,
        .din_channels = 8,
        .pad_size = 1,
        .ain_offset = 2,
        .ain_count = 2,
        .size = 6},
       "response 6 B [DIN PAD AIN AIN]"},
  };
  for (const auto& g : golden) {
    SCOPED_TRACE(int{g.instance});
    for (const IoConfiguration& c : {preset(ConfigurationPreset::kCdn127), odd, bad}) {
      const auto l = produced_assembly_layout(g.instance, c);
      ASSERT_TRUE(l.ok());
      EXPECT_EQ(*l, g.layout);
      EXPECT_EQ(describe(*l), g.text);
    }
  }
}

TEST(PollFormat, FixedConsumedAssemblies) {
  const IoConfiguration bad = config(0x00, 9, 9, 3, 2);
  for (const IoConfiguration& c : {preset(ConfigurationPreset::kCdn127), bad}) {
    // 5: byte 0 outputs.
    EXPECT_EQ(consumed_assembly_layout(5, c).value(), (PollRequestLayout{.dout_offset = 0,
                                                                         .dout_size = 1,
                                                                         .pad_size = 0,
                                                                         .aout_offset = 1,
                                                                         .aout_count = 0,
                                                                         .size = 1}));
    // 100: byte 0 outputs, bytes 1-2 analog output, no pad.
    EXPECT_EQ(consumed_assembly_layout(100, c).value(), (PollRequestLayout{.dout_offset = 0,
                                                                           .dout_size = 1,
                                                                           .pad_size = 0,
                                                                           .aout_offset = 1,
                                                                           .aout_count = 1,
                                                                           .size = 3}));
  }
  EXPECT_EQ(describe(consumed_assembly_layout(100, bad).value()), "request 3 B [DOUT AOUT]");
}

TEST(PollFormat, ConfiguredAssembliesFollowTheConfiguration) {
  const IoConfiguration full = preset(ConfigurationPreset::kCdn127);
  // With the CDN127 preset, 104 is the 4-byte padded request (as the manual's
  // instance 104 table shows: Output States, Pad Byte, Analog Output).
  EXPECT_EQ(consumed_assembly_layout(kDefaultConsumedAssembly, full)->size, 4u);
  EXPECT_EQ(consumed_assembly_layout(kDefaultConsumedAssembly, full)->pad_size, 1u);
  EXPECT_EQ(produced_assembly_layout(kDefaultProducedAssembly, full)->size, 6u);
  // Without DSUP, 103 becomes assembly 102's format.
  const IoConfiguration no_dsup = config(0x06, 8, 8, 2, 1);
  EXPECT_EQ(produced_assembly_layout(103, no_dsup).value(),
            produced_assembly_layout(102, no_dsup).value());
  // DSUP and NoEvenByte: 103 becomes assembly 101's format.
  EXPECT_EQ(produced_assembly_layout(103, config(0x81, 8, 0, 2, 0)).value(),
            produced_assembly_layout(101, full).value());
}

TEST(PollFormat, NoOutputsMeansNoIdleCondition) {
  const PollFormat f = poll_format(config(0x80, 8, 0, 2, 0)).value();
  EXPECT_EQ(f.request.size, 0u);
  EXPECT_FALSE(f.request.has_idle_condition());
  EXPECT_EQ(describe(f.request), "request 0 B [] (no idle condition)");
  EXPECT_TRUE(poll_format(config(0x80, 8, 1, 0, 0))->request.has_idle_condition());
  EXPECT_TRUE(poll_format(config(0x80, 8, 0, 0, 1))->request.has_idle_condition());
}

TEST(PollFormat, PadOnlyAlignsTheAnalogDataOfItsOwnMessage) {
  // The manual's crossed sentence would drop the request pad when there is
  // no analog input; the pad aligns AOUT, so it stays.
  EXPECT_EQ(poll_format(config(0x00, 8, 8, 0, 1))->request.pad_size, 1u);
  // ... and would drop the response pad when there is no analog output.
  EXPECT_EQ(poll_format(config(0x00, 8, 8, 2, 0))->response.pad_size, 1u);
  // No analog data in a message: no pad there.
  EXPECT_EQ(poll_format(config(0x00, 8, 8, 0, 1))->response.pad_size, 0u);
  EXPECT_EQ(poll_format(config(0x00, 8, 8, 2, 0))->request.pad_size, 0u);
  // Analog data already even: no pad (no DOUT; DSUP + DIN).
  EXPECT_EQ(poll_format(config(0x00, 8, 0, 2, 1))->request.pad_size, 0u);
  EXPECT_EQ(poll_format(config(0x80, 8, 0, 2, 1))->response.pad_size, 0u);
  // DSUP alone before AIN: odd, padded.
  EXPECT_EQ(poll_format(config(0x80, 0, 0, 1, 0))->response.pad_size, 1u);
}

TEST(PollFormat, ReservedModeBitsAreIgnored) {
  // 0x86 sets bit 1, shown as 0 in the bit table: the same format as 0x84.
  EXPECT_EQ(poll_format(config(0x86, 8, 8, 2, 1)).value(),
            poll_format(config(0x84, 8, 8, 2, 1)).value());
  EXPECT_EQ(poll_format(config(0xFF, 8, 8, 2, 1)).value(),
            poll_format(config(0x81, 8, 8, 2, 1)).value());
  // NoPollUpdate does not change the format.
  EXPECT_EQ(poll_format(config(0x80, 8, 8, 2, 1)).value(),
            poll_format(config(0x84, 8, 8, 2, 1)).value());
}

TEST(PollFormat, InvalidConfigurationsAreRefused) {
  const IoConfiguration invalid[] = {
      config(0x86, 9, 8, 2, 1),   config(0x86, 8, 9, 2, 1),   config(0x86, 8, 8, 3, 1),
      config(0x86, 8, 8, 2, 2),   config(0x86, 255, 0, 0, 0), config(0x86, 0, 255, 0, 0),
      config(0x86, 0, 0, 255, 0), config(0x86, 0, 0, 0, 255),
  };
  for (const IoConfiguration& c : invalid) {
    EXPECT_EQ(validate(c).error(), Errc::kOutOfRange);
    EXPECT_EQ(poll_format(c).error(), Errc::kOutOfRange);
    EXPECT_EQ(produced_assembly_layout(103, c).error(), Errc::kOutOfRange);
    EXPECT_EQ(consumed_assembly_layout(104, c).error(), Errc::kOutOfRange);
  }
}

TEST(PollFormat, UnknownOrWrongDirectionAssembliesAreRefused) {
  const IoConfiguration c = preset(ConfigurationPreset::kCdn127);
  for (unsigned i = 0; i <= 255; ++i) {
    const auto instance = static_cast<std::uint8_t>(i);
    const bool produced = i == 1 || i == 2 || i == 3 || i == 101 || i == 102 || i == 103;
    const bool consumed = i == 5 || i == 100 || i == 104;
    EXPECT_EQ(produced_assembly_layout(instance, c).ok(), produced) << i;
    EXPECT_EQ(consumed_assembly_layout(instance, c).ok(), consumed) << i;
    if (!produced) {
      EXPECT_EQ(produced_assembly_layout(instance, c).error(), Errc::kOutOfRange);
    }
    if (!consumed) {
      EXPECT_EQ(consumed_assembly_layout(instance, c).error(), Errc::kOutOfRange);
    }
  }
}

}  // namespace
}  // namespace dnbridge::profiles::cdn127
