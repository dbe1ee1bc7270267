// What dnbctl accepts on its command line, and what it refuses.
#include "adapters/dnbctl/values.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace dnbridge::dnbctl {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(ParseUnsigned, TakesDecimalAndHexWithPrefix) {
  EXPECT_EQ(*parse_unsigned("14", 255, "service"), 14u);
  EXPECT_EQ(*parse_unsigned("0x0E", 255, "service"), 14u);
  EXPECT_EQ(*parse_unsigned("0X0e", 255, "service"), 14u);
  EXPECT_EQ(*parse_unsigned(" 7 ", 255, "attribute"), 7u);
  EXPECT_EQ(*parse_unsigned("0xFFFF", 0xFFFF, "class"), 0xFFFFu);
}

TEST(ParseUnsigned, RefusesOutOfRangeWithTheRange) {
  auto v = parse_unsigned("256", 255, "attribute");
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error(), "attribute 256 is out of range 0..255");
  EXPECT_FALSE(parse_unsigned("0x10000", 0xFFFF, "class"));
  // Beyond 64 bits is out of range too, not garbage.
  auto huge = parse_unsigned("99999999999999999999999", 10, "class");
  ASSERT_FALSE(huge);
  EXPECT_NE(huge.error().find("out of range"), std::string::npos);
}

TEST(ParseUnsigned, RefusesWhatIsNotANumber) {
  for (const char* bad : {"", "x", "0x", "-1", "1.5", "12abc", "0xZZ", "+3"}) {
    auto v = parse_unsigned(bad, 1000, "class");
    ASSERT_FALSE(v) << bad;
    EXPECT_NE(v.error().find("is not a number"), std::string::npos) << v.error();
  }
}

TEST(ParseMac, Accepts0To63) {
  EXPECT_EQ(*parse_mac("0"), 0);
  EXPECT_EQ(*parse_mac("63"), 63);
  EXPECT_EQ(*parse_mac("0x3F"), 63);
  auto v = parse_mac("64");
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error(), "MAC ID 64 is out of range 0..63");
}

TEST(Values, NodesByMacOrName) {
  EXPECT_EQ(*parse_node("12"), (NodeRef{12, {}}));
  EXPECT_EQ(*parse_node("0x0C"), (NodeRef{12, {}}));
  EXPECT_EQ(*parse_node(" pump-3 "), (NodeRef{std::nullopt, "pump-3"}));
  EXPECT_EQ(*parse_node("Pumpe \xC3\xA4-2"), (NodeRef{std::nullopt, "Pumpe \xC3\xA4-2"}));
  EXPECT_EQ(*parse_node("3-dry-pump"), (NodeRef{std::nullopt, "3-dry-pump"}));  // not MAC 3
  EXPECT_EQ(*parse_node("0x3G"), (NodeRef{std::nullopt, "0x3G"}));
  // A number out of range is a wrong MAC, never a name.
  EXPECT_FALSE(parse_node("64").ok());
  EXPECT_NE(parse_node("64").error().find("out of range 0..63"), std::string::npos);
  EXPECT_FALSE(parse_node("  ").ok());
}

TEST(ParseOnOff, TakesOnOffAndTheirSynonyms) {
  EXPECT_TRUE(*parse_on_off("on"));
  EXPECT_TRUE(*parse_on_off("ON"));
  EXPECT_TRUE(*parse_on_off("1"));
  EXPECT_FALSE(*parse_on_off("off"));
  EXPECT_FALSE(*parse_on_off("false"));
  EXPECT_FALSE(parse_on_off("maybe"));
}

TEST(ParseAnalog, VoltsRoundToTheNearestStep) {
  // round(V * 4095 / 10): 5.0 V is 2047.5 steps, rounded up to 2048.
  auto v = parse_analog("5.0V");
  ASSERT_TRUE(v) << v.error();
  EXPECT_EQ(v->raw, 2048);
  ASSERT_TRUE(v->volts.has_value());
  EXPECT_DOUBLE_EQ(*v->volts, 5.0);
  EXPECT_EQ(parse_analog("0V")->raw, 0);
  EXPECT_EQ(parse_analog("10V")->raw, 4095);
  EXPECT_EQ(parse_analog("2.5 v")->raw, 1024);    // 1023.75
  EXPECT_EQ(parse_analog("0.001V")->raw, 0);      // 0.41 steps
  EXPECT_EQ(parse_analog("0.002V")->raw, 1);      // 0.82 steps
  EXPECT_EQ(parse_analog("9.9995V")->raw, 4095);  // 4094.8
}

TEST(ParseAnalog, RawCountsAreTakenAsTheyAre) {
  auto v = parse_analog("2048");
  ASSERT_TRUE(v);
  EXPECT_EQ(v->raw, 2048);
  EXPECT_FALSE(v->volts.has_value());
  EXPECT_EQ(parse_analog("0x800")->raw, 2048);
  EXPECT_EQ(parse_analog("4095")->raw, 4095);
  EXPECT_EQ(parse_analog("0")->raw, 0);
}

TEST(ParseAnalog, RefusesOutOfRangeNeverClips) {
  auto volts = parse_analog("11V");
  ASSERT_FALSE(volts);
  EXPECT_EQ(volts.error(), "analog value 11 V is out of range 0..10 V");
  EXPECT_FALSE(parse_analog("10.001V"));
  EXPECT_FALSE(parse_analog("-0.5V"));
  auto raw = parse_analog("4096");
  ASSERT_FALSE(raw);
  EXPECT_EQ(raw.error(), "raw analog value 4096 is out of range 0..4095");
  auto negative = parse_analog("-1");
  ASSERT_FALSE(negative);
  EXPECT_NE(negative.error().find("out of range"), std::string::npos);
}

TEST(ParseAnalog, RefusesAmbiguousOrGarbage) {
  // A decimal point without V: volts or a typo? Not guessed.
  auto v = parse_analog("5.0");
  ASSERT_FALSE(v);
  EXPECT_NE(v.error().find("V suffix"), std::string::npos);
  for (const char* bad : {"", "V", "abcV", "5..0V", "nanV", "infV", "5x"}) {
    EXPECT_FALSE(parse_analog(bad)) << bad;
  }
}

TEST(ParseHexBytes, TakesPairsWithOrWithoutSeparators) {
  EXPECT_EQ(*parse_hex_bytes("0a1B"), (Bytes{0x0A, 0x1B}));
  EXPECT_EQ(*parse_hex_bytes("0A 1b ff"), (Bytes{0x0A, 0x1B, 0xFF}));
  EXPECT_EQ(*parse_hex_bytes("0a:1b"), (Bytes{0x0A, 0x1B}));
  EXPECT_EQ(*parse_hex_bytes("0x0800"), (Bytes{0x08, 0x00}));
  EXPECT_EQ(*parse_hex_bytes(""), Bytes{});
}

TEST(ParseHexBytes, RefusesOddDigitsAndNonHex) {
  auto odd = parse_hex_bytes("abc");
  ASSERT_FALSE(odd);
  EXPECT_NE(odd.error().find("two hex digits"), std::string::npos);
  EXPECT_FALSE(parse_hex_bytes("a bc"));  // a lone digit before a separator
  auto bad = parse_hex_bytes("0g");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("'g' is not a hex digit"), std::string::npos);
}

TEST(HexBytes, UpperCaseSpaceSeparated) {
  EXPECT_EQ(hex_bytes(Bytes{0x06, 0x43, 0xff}), "06 43 FF");
  EXPECT_EQ(hex_bytes(Bytes{}), "");
}

TEST(DecodeData, ShortString) {
  // 06 'C' 'D' 'N' '1' '2' '7': the CDN127's product name (Identity, attribute 7).
  const Bytes name{0x06, 'C', 'D', 'N', '1', '2', '7'};
  EXPECT_EQ(*decode_data(name, Decoding::kString), "CDN127");
  EXPECT_FALSE(decode_data(Bytes{0x07, 'C', 'D'}, Decoding::kString));  // truncated
  EXPECT_FALSE(decode_data(Bytes{0x01, 'C', 'D'}, Decoding::kString));  // bytes follow
  EXPECT_FALSE(decode_data(Bytes{}, Decoding::kString));
}

TEST(DecodeData, LittleEndianIntegers) {
  EXPECT_EQ(*decode_data(Bytes{0x3B, 0x00}, Decoding::kUint), "59");  // vendor ID, UINT
  EXPECT_EQ(*decode_data(Bytes{0x60, 0x07}, Decoding::kUint), "1888");
  EXPECT_EQ(*decode_data(Bytes{0xFF}, Decoding::kUint), "255");
  EXPECT_EQ(*decode_data(Bytes{0xFF}, Decoding::kInt), "-1");
  EXPECT_EQ(*decode_data(Bytes{0x00, 0x80}, Decoding::kInt), "-32768");
  EXPECT_EQ(*decode_data(Bytes{0xFF, 0x7F}, Decoding::kInt), "32767");
  EXPECT_EQ(*decode_data(Bytes{0x78, 0x56, 0x34, 0x12}, Decoding::kUint), "305419896");
  EXPECT_EQ(*decode_data(Bytes(8, 0xFF), Decoding::kUint), "18446744073709551615");
  EXPECT_EQ(*decode_data(Bytes(8, 0xFF), Decoding::kInt), "-1");
  auto odd = decode_data(Bytes{1, 2, 3}, Decoding::kUint);
  ASSERT_FALSE(odd);
  EXPECT_NE(odd.error().find("1, 2, 4 or 8 bytes"), std::string::npos);
  EXPECT_FALSE(decode_data(Bytes{}, Decoding::kInt));
}

TEST(ParseDecoding, NamesOnly) {
  EXPECT_EQ(*parse_decoding("string"), Decoding::kString);
  EXPECT_EQ(*parse_decoding("uint"), Decoding::kUint);
  EXPECT_EQ(*parse_decoding("int"), Decoding::kInt);
  EXPECT_FALSE(parse_decoding("float"));
}

}  // namespace
}  // namespace dnbridge::dnbctl
