// The objects of a simulated device described by an EDS file (the io-block
// example), request by request: Identity from [Device]; the Assembly
// object's member lists, which agree with the EDS they come from, and data
// packed from the parameters; the Parameter object within its limits; the
// Acknowledge Handler's defaults and limits; CIP errors for the rest.
#include "adapters/sim/generic/eds_objects.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "bridge/cip/assembly.hpp"
#include "bridge/profiles/eds/member_check.hpp"

namespace dnbridge::sim {
namespace {

constexpr std::uint8_t kGet = 0x0E;
constexpr std::uint8_t kSet = 0x10;

profiles::eds::EdsFile io_block() {
  std::ifstream in(std::string(DNBRIDGE_EDS_DIR) + "/dnbridge-example-io-block.eds");
  std::stringstream text;
  text << in.rdbuf();
  auto parsed = profiles::eds::parse(text.str());
  EXPECT_TRUE(parsed.file.has_value());
  return parsed.file.value_or(profiles::eds::EdsFile{});
}

// The response message of `objects` to a request: service byte first.
std::vector<std::uint8_t> execute(EdsObjects& objects, std::uint8_t service, std::uint16_t class_id,
                                  std::uint16_t instance, std::uint8_t attribute,
                                  std::vector<std::uint8_t> data = {}) {
  devicenet::RequestMessage r;
  r.service = service;
  r.class_id = class_id;
  r.instance_id = instance;
  r.attribute = attribute;
  r.data = Bytes(data.data(), data.size());
  std::array<std::uint8_t, devicenet::kMaxExplicitMessage> out{};
  const std::size_t n = objects.execute(r, MutableBytes(out));
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

// The general status of an error response; 0 for success.
std::uint8_t status(const std::vector<std::uint8_t>& response) {
  return !response.empty() && response[0] == 0x94 && response.size() >= 2 ? response[1] : 0;
}

class EdsObjectsTest : public ::testing::Test {
 protected:
  std::vector<std::uint8_t> call(std::uint8_t service, std::uint16_t class_id,
                                 std::uint16_t instance, std::uint8_t attribute,
                                 std::vector<std::uint8_t> data = {}) {
    return execute(objects_, service, class_id, instance, attribute, std::move(data));
  }
  std::vector<std::uint8_t> get(std::uint16_t c, std::uint16_t i, std::uint8_t a) {
    auto r = call(kGet, c, i, a);
    EXPECT_FALSE(r.empty());
    if (r.empty() || r[0] != (kGet | 0x80)) {
      ADD_FAILURE() << "Get " << c << "/" << i << "/" << int{a} << " failed";
      return {};
    }
    return {r.begin() + 1, r.end()};
  }

  EdsObjects objects_{io_block(), 0x12345678};
};

TEST_F(EdsObjectsTest, IdentityIsTheEdsDevice) {
  EXPECT_EQ(get(1, 1, 1), (std::vector<std::uint8_t>{0xE9, 0xFD}));  // 65001
  EXPECT_EQ(get(1, 1, 3), (std::vector<std::uint8_t>{0x01, 0x00}));
  EXPECT_EQ(get(1, 1, 4), (std::vector<std::uint8_t>{1, 3}));
  EXPECT_EQ(get(1, 1, 6), (std::vector<std::uint8_t>{0x78, 0x56, 0x34, 0x12}));
  const auto name = get(1, 1, 7);
  ASSERT_FALSE(name.empty());
  EXPECT_EQ(std::string(name.begin() + 1, name.end()), "Example IO block 8DI/8DO/1AI");
  EXPECT_EQ(name[0], name.size() - 1);
}

TEST_F(EdsObjectsTest, AssemblyMemberListsAgreeWithTheirEds) {
  EXPECT_EQ(get(4, 0, 2), (std::vector<std::uint8_t>{150, 0}));  // max instance
  EXPECT_EQ(get(4, 100, 1), (std::vector<std::uint8_t>{3, 0}));
  const auto list = get(4, 100, 2);
  auto members = cip::decode_member_list(Bytes(list.data(), list.size()));
  ASSERT_TRUE(members.ok());
  ASSERT_EQ(members->size(), 3u);
  EXPECT_EQ(cip::describe((*members)[1]), "8 bits: class 0x0F instance 0x05 attribute 0x01");
  const profiles::eds::EdsFile& f = objects_.file();
  EXPECT_TRUE(
      profiles::eds::member_differences(f, *f.assembly_at(f.io.input(1)->path), *members).empty());
  const auto outputs = get(4, 150, 2);
  auto out_members = cip::decode_member_list(Bytes(outputs.data(), outputs.size()));
  ASSERT_TRUE(out_members.ok());
  ASSERT_EQ(out_members->size(), 2u);
  EXPECT_TRUE((*out_members)[1].padding());
  EXPECT_EQ(status(call(kGet, 4, 101, 1)), 0x16);
}

TEST_F(EdsObjectsTest, AssemblyDataPacksTheParameters) {
  const std::array<std::uint8_t, 1> inputs{0xA5};
  const std::array<std::uint8_t, 1> module{0x01};
  const std::array<std::uint8_t, 2> analog{0xFE, 0xFF};  // -2 mV
  ASSERT_TRUE(objects_.set_param_value(3, Bytes(inputs.data(), 1)));
  ASSERT_TRUE(objects_.set_param_value(5, Bytes(module.data(), 1)));
  ASSERT_TRUE(objects_.set_param_value(2, Bytes(analog.data(), 2)));
  EXPECT_EQ(get(4, 100, 3), (std::vector<std::uint8_t>{0xA5, 0x01, 0xFE, 0xFF}));
  EXPECT_EQ(objects_.assembly_data(100), (std::vector<std::uint8_t>{0xA5, 0x01, 0xFE, 0xFF}));
  EXPECT_EQ(status(call(kSet, 4, 100, 3, {0, 0, 0, 0})), 0x0E);  // set through a connection only
}

TEST_F(EdsObjectsTest, ParametersAreSetWithinTheirLimits) {
  EXPECT_EQ(get(0x0F, 1, 1), (std::vector<std::uint8_t>{3, 0}));  // its default
  EXPECT_EQ(status(call(kSet, 0x0F, 1, 1, {50, 0})), 0);
  EXPECT_EQ(get(0x0F, 1, 1), (std::vector<std::uint8_t>{50, 0}));
  EXPECT_EQ(status(call(kSet, 0x0F, 1, 1, {101, 0})), 0x09);  // above 100
  EXPECT_EQ(status(call(kSet, 0x0F, 1, 1, {50})), 0x13);
  EXPECT_EQ(status(call(kSet, 0x0F, 1, 1, {50, 0, 0})), 0x15);
  EXPECT_EQ(status(call(kSet, 0x0F, 2, 1, {0, 0})), 0x0E);  // read only
  EXPECT_EQ(status(call(kSet, 0x0F, 10, 1, {0})), 0x16);    // no Param10
  EXPECT_EQ(get(0x0F, 0, 2), (std::vector<std::uint8_t>{9, 0}));
}

TEST_F(EdsObjectsTest, TheAcknowledgeHandlerHasTheSeedsDefaultsAndLimits) {
  EXPECT_EQ(get(0x2B, 1, 1), (std::vector<std::uint8_t>{20, 0}));
  EXPECT_EQ(get(0x2B, 1, 2), (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(get(0x2B, 1, 3), (std::vector<std::uint8_t>{4, 0}));
  EXPECT_EQ(get(0x2B, 1, 4), (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(get(0x2B, 1, 5), (std::vector<std::uint8_t>{0}));  // an empty list
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 1, {50, 0})), 0);
  EXPECT_EQ(objects_.ack_handler().ack_timer_ms, 50);
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 1, {0, 0})), 0x09);  // 1..65535
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 5, {1, 4})), 0x0E);
  objects_.ack_handler().cos_acknowledged = true;
  EXPECT_EQ(get(0x2B, 1, 5), (std::vector<std::uint8_t>{1, 4}));
  EXPECT_EQ(get(0x2B, 0, 1), (std::vector<std::uint8_t>{1, 0}));
}

TEST_F(EdsObjectsTest, WhatIsNotThereIsAnsweredWithItsError) {
  EXPECT_EQ(status(call(0x05, 1, 1, 0)), 0x08);          // Reset: not a service here
  EXPECT_EQ(status(call(kGet, 0x64, 1, 1)), 0x16);       // no such class
  EXPECT_EQ(status(call(kGet, 1, 1, 99)), 0x14);         // no such attribute
  EXPECT_EQ(status(call(kSet, 1, 1, 1, {0, 0})), 0x0E);  // Identity: read only
}

TEST_F(EdsObjectsTest, RequestsAreCheckedInTheCdn127SimulatorsOrder) {
  EXPECT_EQ(status(call(kSet, 0x0F, 0, 2, {0, 0})), 0x08);     // no Set at class level
  EXPECT_EQ(status(call(kSet, 0x0F, 1, 7, {0, 0})), 0x14);     // no such attribute
  EXPECT_EQ(status(call(kGet, 0x0F, 1, 1, {0})), 0x15);        // a Get carries no data
  EXPECT_EQ(get(1, 0, 1), (std::vector<std::uint8_t>{1, 0}));  // Identity's class revision
  EXPECT_EQ(get(4, 0, 1), (std::vector<std::uint8_t>{1, 0}));  // Assembly's: the seed's 1
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 1, {50})), 0x13);
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 2, {3, 0})), 0x15);
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 2, {3})), 0);
  EXPECT_EQ(objects_.ack_handler().retry_limit, 3);
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 3, {0x00, 0x01})), 0x09);  // 256: not a USINT
  EXPECT_EQ(status(call(kSet, 0x2B, 1, 3, {5, 0})), 0);
  EXPECT_EQ(objects_.ack_handler().cos_producing_instance, 5);
}

// A device of its own EDS: members at bit offsets, a nested assembly, a REAL
// parameter, a string parameter.
profiles::eds::EdsFile packed_device() {
  auto parsed = profiles::eds::parse(R"(
[Device]
VendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;
[Params]
Param1 = 0, 0, , 0, 0xC6, 1, "nibble", "", "", 0, 15, 5;
Param2 = 0, 0, , 0, 0xC1, 1, "flag", "", "", 0, 1, 1;
Param3 = 0, 0, , 0, 0xCA, 4, "ratio", "", "", -1, 0.1, 0.1;
Param4 = 0, 0, , 0, 0xDA, 8, "label", "", "";
[Assembly]
Assem1 = "outer", "20 04 24 01 30 03", 16, 0, , , 4, Param1, 1, Param2, 3, , 8, Assem2;
Assem2 = "inner", "20 04 24 02 30 03", 8, 0, , , 4, Param1, 4, ;
)");
  EXPECT_TRUE(parsed.file.has_value());
  return parsed.file.value_or(profiles::eds::EdsFile{});
}

TEST(EdsObjectsPacking, MembersArePackedAtTheirBitsAndNestedAssembliesInside) {
  EdsObjects objects(packed_device(), 1);
  // nibble 5 in bits 0..3, flag in bit 4, 3 pad bits, then Assem2: nibble 5, 4 pad bits.
  EXPECT_EQ(objects.assembly_data(1), (std::vector<std::uint8_t>{0x15, 0x05}));
  const std::array<std::uint8_t, 1> nibble{0x0A};
  ASSERT_TRUE(objects.set_param_value(1, Bytes(nibble.data(), 1)));
  EXPECT_EQ(objects.assembly_data(1), (std::vector<std::uint8_t>{0x1A, 0x0A}));
}

TEST(EdsObjectsPacking, ARealIsSetWithinItsLimitsAsARealAndNeverToNaN) {
  EdsObjects objects(packed_device(), 1);
  const auto set_float = [&](float f) {
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return status(
        execute(objects, kSet, 0x0F, 3, 1,
                {static_cast<std::uint8_t>(bits), static_cast<std::uint8_t>(bits >> 8),
                 static_cast<std::uint8_t>(bits >> 16), static_cast<std::uint8_t>(bits >> 24)}));
  };
  EXPECT_EQ(set_float(0.1f), 0);  // its maximum, as a REAL
  EXPECT_EQ(set_float(0.2f), 0x09);
  EXPECT_EQ(set_float(std::numeric_limits<float>::quiet_NaN()), 0x09);
  EXPECT_EQ(set_float(-std::numeric_limits<float>::infinity()), 0x09);
  EXPECT_FLOAT_EQ(static_cast<float>(objects.param_number(3).value_or(0)), 0.1f);
}

TEST(EdsObjectsPacking, AStringParameterIsKeptEmptyAndNotSettable) {
  EdsObjects objects(packed_device(), 1);
  EXPECT_EQ(execute(objects, kGet, 0x0F, 4, 1),
            (std::vector<std::uint8_t>{kGet | 0x80, 0x00}));  // SHORT_STRING, length 0
  EXPECT_EQ(status(execute(objects, kSet, 0x0F, 4, 1, {1, 'a', 0, 0, 0, 0, 0, 0})), 0x0E);
}

}  // namespace
}  // namespace dnbridge::sim
