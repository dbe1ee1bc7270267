// An I/O connection's data as named, typed fields from the EDS's assembly
// members: the example I/O block's input and output, nested assemblies,
// path members and padding, signed and REAL values, scaling, and commands
// encoded field by field with every refusal said.
#include "bridge/profiles/eds/io_layout.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/support/example_eds.hpp"

namespace dnbridge::profiles::eds {
namespace {

using ::testing::HasSubstr;

using ByteVec = std::vector<std::uint8_t>;

const DataType& type(std::uint8_t code) { return *data_type(code); }

IoLayout input1(const EdsFile& f) { return layout_of(f, *f.io.input(1)); }
IoLayout output1(const EdsFile& f) { return layout_of(f, *f.io.output(1)); }

TEST(EdsIoLayout, TheIoBlocksInputIsItsAssemblysParametersAtTheirBits) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  const IoLayout in = input1(f);
  EXPECT_EQ(in.size, 4);
  EXPECT_EQ(in.name, "Inputs and status");
  EXPECT_EQ(in.assembly, "Assem100 (Inputs and status)");
  ASSERT_EQ(in.fields.size(), 3u);
  EXPECT_EQ(in.fields[0].name, "Digital inputs");
  EXPECT_EQ(in.fields[0].offset, 0u);
  EXPECT_EQ(in.fields[0].bits, 8);
  EXPECT_EQ(in.fields[0].type.name, "USINT");
  EXPECT_EQ(in.fields[1].name, "Module status");
  EXPECT_EQ(in.fields[1].offset, 8u);
  EXPECT_EQ(in.fields[2].name, "Analog input 1");
  EXPECT_EQ(in.fields[2].offset, 16u);
  EXPECT_EQ(in.fields[2].bits, 16);
  EXPECT_EQ(in.fields[2].units, "mV");
  EXPECT_EQ(in.fields[2].param, 2u);
  EXPECT_TRUE(in.fields[2].numeric);
  EXPECT_EQ(in.field("analog INPUT 1"), &in.fields[2]);
}

TEST(EdsIoLayout, DecodesEachFieldAsItsTypeReadsIt) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  const IoLayout in = input1(f);
  const ByteVec data{0xA5, 0x01, 0x18, 0xFC};  // analog input 0xFC18: -1000 mV
  const auto values = decode(in, Bytes(data.data(), data.size()));
  ASSERT_EQ(values.size(), 3u);
  EXPECT_EQ(values[0].value, 165);
  EXPECT_EQ(values[1].value, 1);
  EXPECT_EQ(values[2].field, 2u);
  EXPECT_EQ(values[2].raw, 0xFC18u);
  EXPECT_EQ(values[2].value, -1000);
  EXPECT_EQ(values[2].shown, -1000);
  // A response cut short: the fields it still holds.
  EXPECT_EQ(decode(in, Bytes(data.data(), 2)).size(), 2u);
}

TEST(EdsIoLayout, EncodesACommandFieldByFieldWithPaddingZero) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  const IoLayout out = output1(f);
  ASSERT_EQ(out.fields.size(), 1u);  // the pad byte is no field
  auto data = encode(out, {{"digital outputs", 0x81}});
  ASSERT_TRUE(data.ok());
  EXPECT_EQ(*data, (ByteVec{0x81, 0x00}));
}

TEST(EdsIoLayout, RefusesACommandThatDoesNotFitAndSaysWhy) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  const IoLayout out = output1(f);
  std::string why;
  EXPECT_EQ(encode(out, {}, &why).error(), make_error_code(Errc::kMalformed));
  EXPECT_EQ(why, "Digital outputs is not given");
  EXPECT_EQ(encode(out, {{"Digital output", 1}}, &why).error(), make_error_code(Errc::kMalformed));
  EXPECT_EQ(why, "no field \"Digital output\"");
  EXPECT_EQ(encode(out, {{"Digital outputs", 1}, {"Digital outputs", 2}}, &why).error(),
            make_error_code(Errc::kMalformed));
  EXPECT_EQ(why, "Digital outputs is given twice");
  EXPECT_EQ(encode(out, {{"Digital outputs", 256}}, &why).error(),
            make_error_code(Errc::kOutOfRange));
  EXPECT_EQ(why, "Digital outputs: 256 is outside 0..255");
  EXPECT_EQ(encode(out, {{"Digital outputs", 1.5}}, &why).error(),
            make_error_code(Errc::kOutOfRange));
  EXPECT_EQ(why, "Digital outputs: 1.5 is not a USINT of 8 bits");
  EXPECT_FALSE(encode(out, {{"Digital outputs", NAN}}).ok());
}

// Assem1: 8 bits of Assem2 (Param1, a SINT of 4 bits, then 4 of padding),
// 4 bits at a path, 4 of padding, then Param2, a REAL of 32 bits scaled by
// 10 / 4 with offset 1.
constexpr const char* kNested =
    "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
    "[IO_Info]\nPollInfo = 1, 1, 0;\n"
    "Input1 = 6, 0, 1, \"in\", 6, \"20 04 24 01 30 03\", \"\";\n"
    "[Params]\n"
    "Param1 = 0, 0, , 0, 0xC2, 1, \"small\", \"\", \"\", -8, 7, 0;\n"
    "Param2 = 0, 0, , 0, 0xCA, 4, \"flow\", \"l/min\", \"\", , , 0, 10, 4, 1, 1;\n"
    "[Assembly]\n"
    "Assem1 = \"outer\", \"20 04 24 01 30 03\", 48, 0, , , 8, Assem2, 4, \"20 09 24 01 30 03\", "
    "4, , 32, Param2;\n"
    "Assem2 = \"inner\", \"20 04 24 02 30 03\", 8, 0, , , 4, Param1, 4, ;\n";

TEST(EdsIoLayout, UnfoldsNestedAssembliesAndNamesPathMembersByTheirPath) {
  auto parsed = parse(kNested);
  ASSERT_TRUE(parsed.file.has_value());
  const IoLayout in = input1(*parsed.file);
  ASSERT_EQ(in.fields.size(), 3u);
  EXPECT_EQ(in.fields[0].name, "small");
  EXPECT_EQ(in.fields[0].offset, 0u);
  EXPECT_EQ(in.fields[0].bits, 4);
  EXPECT_EQ(in.fields[1].name, "class 0x09 instance 0x01 attribute 0x03");
  EXPECT_EQ(in.fields[1].type.name, "bits");
  EXPECT_EQ(in.fields[1].offset, 8u);
  EXPECT_EQ(in.fields[2].name, "flow");
  EXPECT_EQ(in.fields[2].offset, 16u);

  // small = -3 in 4 bits (0xD), the path's bits 0xA, flow 2.5 as a REAL.
  auto data =
      encode(in, {{"small", -3}, {"class 0x09 instance 0x01 attribute 0x03", 10}, {"flow", 2.5}});
  ASSERT_TRUE(data.ok());
  const auto flow = std::bit_cast<std::uint32_t>(2.5F);
  EXPECT_EQ(
      *data,
      (ByteVec{0x0D, 0x0A, static_cast<std::uint8_t>(flow), static_cast<std::uint8_t>(flow >> 8),
               static_cast<std::uint8_t>(flow >> 16), static_cast<std::uint8_t>(flow >> 24)}));
  const auto values = decode(in, Bytes(data->data(), data->size()));
  ASSERT_EQ(values.size(), 3u);
  EXPECT_EQ(values[0].value, -3);
  EXPECT_EQ(values[1].value, 10);
  EXPECT_EQ(values[2].value, 2.5);
  EXPECT_EQ(values[2].shown, (2.5 + 1) * 10 / 4);
  std::string why;
  EXPECT_FALSE(
      encode(in, {{"small", 8}, {"class 0x09 instance 0x01 attribute 0x03", 0}, {"flow", 0}}, &why)
          .ok());
  EXPECT_EQ(why, "small: 8 is outside -8..7");
}

TEST(EdsIoLayout, ValuesTakeTheirTypesRangeWithinTheirBits) {
  EXPECT_EQ(to_raw(type(0xC3), 16, -1), 0xFFFFu);
  EXPECT_EQ(from_raw(type(0xC3), 16, 0xFFFF), -1);
  EXPECT_EQ(to_raw(type(0xC2), 4, -8), 0x8u);
  EXPECT_EQ(from_raw(type(0xC2), 4, 0x8), -8);
  EXPECT_FALSE(to_raw(type(0xC2), 4, 8));
  EXPECT_FALSE(to_raw(type(0xC7), 16, 65536));
  EXPECT_EQ(to_raw(type(0xC7), 16, 65535), 0xFFFFu);
  EXPECT_FALSE(to_raw(type(0xC7), 16, -1));
  EXPECT_EQ(to_raw(type(0xC1), 1, 1), 1u);
  EXPECT_FALSE(to_raw(type(0xC1), 1, 2));
  EXPECT_EQ(to_raw(type(0xC9), 64, 18446744073709549568.0), 0xFFFFFFFFFFFFF800u);
  EXPECT_FALSE(to_raw(type(0xC9), 64, 18446744073709551616.0));
  EXPECT_EQ(from_raw(type(0xC5), 64, 0x8000000000000000), -9223372036854775808.0);
  EXPECT_FALSE(to_raw(type(0xCA), 32, 1e39));
  EXPECT_FALSE(to_raw(type(0xCA), 16, 1.0));  // a REAL needs its 32 bits
  EXPECT_EQ(from_raw(type(0xCB), 64, std::bit_cast<std::uint64_t>(-0.25)), -0.25);
  EXPECT_FALSE(to_raw(type(0xC6), 8, INFINITY));
}

// Two outputs of one name, as channel parameters often are; a REAL limited
// to 0.1.
constexpr const char* kTwins =
    "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
    "[IO_Info]\nPollInfo = 1, 0, 1;\n"
    "Output1 = 6, 0, 1, \"out\", 6, \"20 04 24 02 30 03\", \"\";\n"
    "[Params]\n"
    "Param1 = 0, 0, , 0, 0xC6, 1, \"Channel\", \"\", \"\", 0, 10, 0;\n"
    "Param2 = 0, 0, , 0, 0xC6, 1, \"channel\", \"\", \"\", 0, 10, 0;\n"
    "Param3 = 0, 0, , 0, 0xCA, 4, \"gain\", \"\", \"\", 0, 0.1, 0;\n"
    "[Assembly]\n"
    "Assem2 = \"out\", \"20 04 24 02 30 03\", 48, 0, , , 8, Param1, 8, Param2, 32, Param3;\n";

TEST(EdsIoLayout, FieldsOfOneNameAreNamedByTheirParameter) {
  auto parsed = parse(kTwins);
  ASSERT_TRUE(parsed.file.has_value());
  const IoLayout out = layout_of(*parsed.file, *parsed.file->io.output(1));
  EXPECT_EQ(out.field("channel"), nullptr);
  EXPECT_EQ(out.fields_named("channel"), 2u);
  EXPECT_EQ(out.field("Param2"), &out.fields[1]);
  std::string why;
  EXPECT_FALSE(encode(out, {{"Channel", 1}, {"gain", 0}}, &why).ok());
  EXPECT_EQ(why, "\"Channel\" names 2 fields: name one as ParamN");
  auto data = encode(out, {{"Param1", 1}, {"param2", 2}, {"gain", 0}}, &why);
  ASSERT_TRUE(data.ok()) << why;
  EXPECT_EQ((*data)[0], 1);
  EXPECT_EQ((*data)[1], 2);
}

TEST(EdsIoLayout, AREALsLimitHoldsForTheValueAsSent) {
  auto parsed = parse(kTwins);
  ASSERT_TRUE(parsed.file.has_value());
  const IoLayout out = layout_of(*parsed.file, *parsed.file->io.output(1));
  std::string why;
  // 0.1 as a float is 0.100000001...: above the limit 0.1 as the device
  // would take it.
  EXPECT_EQ(encode(out, {{"Param1", 0}, {"Param2", 0}, {"gain", 0.1}}, &why).error(),
            make_error_code(Errc::kOutOfRange));
  EXPECT_THAT(why, HasSubstr("gain: 0.10000000149011612 is outside 0..0.1"));
  EXPECT_TRUE(encode(out, {{"Param1", 0}, {"Param2", 0}, {"gain", 0.0999999}}).ok());
}

TEST(EdsIoLayout, DataToSendHasItsSizeEveryFieldWithinItsLimitsAndPaddingZero) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  const IoLayout out = output1(f);
  std::string why;
  const ByteVec ok{0x81, 0x00};
  EXPECT_TRUE(check(out, Bytes(ok.data(), ok.size()), &why).ok()) << why;
  const ByteVec pad{0x81, 0x10};
  EXPECT_EQ(check(out, Bytes(pad.data(), pad.size()), &why).error(),
            make_error_code(Errc::kOutOfRange));
  EXPECT_EQ(why,
            "bit 4 of byte 1 is set, and the EDS gives it no field (padding, or a field that is "
            "not a number): it must be 0");
  const ByteVec shorter{0x81};
  EXPECT_EQ(check(out, Bytes(shorter.data(), shorter.size()), &why).error(),
            make_error_code(Errc::kMalformed));
  EXPECT_EQ(why, "1 bytes given, \"Outputs\" is 2 bytes");
  // A field beyond its EDS limits (the analog input: -10000..10000 mV).
  const IoLayout in = input1(f);
  const ByteVec beyond{0x00, 0x00, 0x11, 0x27};  // 10001
  EXPECT_EQ(check(in, Bytes(beyond.data(), beyond.size()), &why).error(),
            make_error_code(Errc::kOutOfRange));
  EXPECT_EQ(why, "Analog input 1: 10001 is outside -10000..10000");
  // Data the EDS describes no field of is sent as given.
  IoLayout bare = out;
  bare.fields.clear();
  EXPECT_TRUE(check(bare, Bytes(pad.data(), pad.size())).ok());
}

}  // namespace
}  // namespace dnbridge::profiles::eds
