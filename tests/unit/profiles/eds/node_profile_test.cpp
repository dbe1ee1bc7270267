// A node described by its EDS as the master takes it: identity, the poll
// connection's paths and sizes, the parameters and then the safe state as
// settings at their link paths, and each refusal said with the parameter.
#include "bridge/profiles/eds/node_profile.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "bridge/cip/assembly.hpp"
#include "tests/support/example_eds.hpp"

namespace dnbridge::profiles::eds {
namespace {

using ::testing::HasSubstr;
using ByteVec = std::vector<std::uint8_t>;

const std::vector<ParameterValue> kSafeState{{"Output fault action", 0},
                                             {"Output fault value", 0},
                                             {"Output idle action", 0},
                                             {"output idle value", 0x80}};

// The profile of `node` for a copy of `file`.
Result<devicenet::NodeProfile> profile_of(const EdsFile& file, const EdsNode& node,
                                          std::string* why = nullptr) {
  return make_node_profile(std::make_shared<const EdsFile>(file), node, why);
}

EdsNode polled(std::vector<ParameterValue> parameters = {}) {
  EdsNode n;
  n.parameters = std::move(parameters);
  n.safe_state = kSafeState;
  return n;
}

TEST(EdsNodeProfile, TheIoBlockPolledWithItsParametersThenItsSafeState) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  std::string why;
  auto p = profile_of(f, polled({{"Input filter", 5}}), &why);
  ASSERT_TRUE(p.ok()) << why;
  EXPECT_EQ(p->identity, (devicenet::ExpectedIdentity{65001, 7, 1}));
  EXPECT_EQ(p->produced_path, (ByteVec{0x20, 0x04, 0x24, 0x64, 0x30, 0x03}));
  EXPECT_EQ(p->consumed_path, (ByteVec{0x20, 0x04, 0x24, 0x96, 0x30, 0x03}));
  EXPECT_EQ(p->produced_size, 4u);
  EXPECT_EQ(p->consumed_size, 2u);
  EXPECT_EQ(p->format_description,
            "input 4 B \"Inputs and status\" = Assem100 (Inputs and status), output 2 B "
            "\"Outputs\" = Assem150 (Outputs)");
  EXPECT_FALSE(p->has_size_fallback);
  ASSERT_EQ(p->settings.size(), 5u);
  const auto& filter = p->settings[0];
  EXPECT_EQ(filter.class_id, 0x0F);
  EXPECT_EQ(filter.instance_id, 1);
  EXPECT_EQ(filter.attribute, 1);
  EXPECT_EQ(filter.value, (ByteVec{5, 0}));  // UINT
  EXPECT_EQ(filter.name, "Param1 Input filter");
  EXPECT_FALSE(filter.keep_device_value);
  EXPECT_EQ(p->settings[1].name, "Param6 Output fault action");
  EXPECT_EQ(p->settings[1].instance_id, 6);
  EXPECT_EQ(p->settings[4].name, "Param9 Output idle value");
  EXPECT_EQ(p->settings[4].value, (ByteVec{0x80}));
}

TEST(EdsNodeProfile, TheDevicesMemberListsAreCheckedAgainstTheEds) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  auto p = profile_of(f, polled());
  ASSERT_TRUE(p.ok());
  ASSERT_EQ(p->checks.size(), 2u);
  const auto& in = p->checks[0];
  EXPECT_EQ(in.class_id, 4);
  EXPECT_EQ(in.instance_id, 100);
  EXPECT_EQ(in.attribute, 2);
  EXPECT_EQ(in.name, "Assembly 100 member list (Assem100 Inputs and status)");
  EXPECT_EQ(p->checks[1].instance_id, 150);
  // As the EDS lists them: Param3, Param5, Param2 at their link paths.
  const auto member = [](std::uint16_t bits, std::uint8_t instance) {
    cip::AssemblyMember m;
    m.bits = bits;
    m.path_bytes = {0x20, 0x0F, 0x24, instance, 0x30, 0x01};
    m.path = cip::decode_epath(Bytes(m.path_bytes.data(), m.path_bytes.size())).value();
    return m;
  };
  const auto agreeing = cip::encode_member_list({member(8, 3), member(8, 5), member(16, 2)});
  EXPECT_TRUE(in.verifier->differences(Bytes(agreeing.data(), agreeing.size())).empty());
  const auto swapped = cip::encode_member_list({member(8, 5), member(8, 3), member(16, 2)});
  const auto d = in.verifier->differences(Bytes(swapped.data(), swapped.size()));
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0],
            "member 1: class 0x0F instance 0x05 attribute 0x01 on the device, Param3 (Digital "
            "inputs), class 0x0F instance 0x03 attribute 0x01 in the EDS");
  const std::vector<std::uint8_t> cut{0x08, 0x00, 0x06};
  EXPECT_EQ(in.verifier->differences(Bytes(cut.data(), cut.size())).at(0),
            "the device's member list does not decode (input truncated)");
  // Two profiles of one EDS compare equal (a reload sees no change); one
  // whose EDS lists other members does not.
  EXPECT_EQ(*p, profile_of(f, polled()).value());
  EdsFile other = f;
  for (auto& a : other.assemblies) {
    if (a.number == 100) std::swap(a.members[0], a.members[1]);
  }
  EXPECT_NE(*p, profile_of(other, polled()).value());
}

TEST(EdsNodeProfile, OutputsWithoutASafeStateAreRefused) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  EdsNode n;
  std::string why;
  EXPECT_EQ(profile_of(f, n, &why).error(), make_error_code(Errc::kMalformed));
  EXPECT_EQ(why,
            "the node has outputs (output 2 B \"Outputs\" = Assem150 (Outputs)) and no safe "
            "state: give the parameters that set their fault and idle actions "
            "(safe_state_parameters), or safe_state = \"device\" where the device's maker fixes "
            "them");
}

// safe_state = "device": nothing of the safe state is written; the
// parameters the EDS names for it are read and kept, after the node's own.
TEST(EdsNodeProfile, TheDevicesOwnSafeStateIsReadAndKeptNeverWritten) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  EdsNode n;
  n.parameters = {{"Input filter", 5}};
  n.safe_state_of_device = true;
  std::string why;
  auto p = profile_of(f, n, &why);
  ASSERT_TRUE(p.ok()) << why;
  ASSERT_EQ(p->settings.size(), 5u);
  EXPECT_FALSE(p->settings[0].keep_device_value);  // the parameter, set
  std::vector<std::string> kept;
  for (std::size_t i = 1; i < p->settings.size(); ++i) {
    const auto& s = p->settings[i];
    EXPECT_TRUE(s.keep_device_value) << s.name;
    EXPECT_EQ(std::uint64_t{s.device_value_max} + 1, 1ull << (8 * s.value.size())) << s.name;
    kept.push_back(s.name);
  }
  EXPECT_EQ(kept,
            (std::vector<std::string>{"Param6 Output fault action", "Param7 Output fault value",
                                      "Param8 Output idle action", "Param9 Output idle value"}));
  // The device's own and parameters at once is no safe state.
  n.safe_state = {{"Output idle action", 0}};
  EXPECT_EQ(profile_of(f, n, &why).error(), make_error_code(Errc::kMalformed));
  EXPECT_EQ(why, "safe_state_parameters: given with safe_state = \"device\" (the device's own)");
}

struct Refusal {
  const char* what;
  std::vector<ParameterValue> parameters;
  Errc code;
  const char* why;
};

class EdsNodeProfileRefusal : public ::testing::TestWithParam<Refusal> {};

TEST_P(EdsNodeProfileRefusal, NamesTheParameterAndWhatIsWrong) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  std::string why;
  auto p = profile_of(f, polled(GetParam().parameters), &why);
  ASSERT_FALSE(p.ok()) << GetParam().what;
  EXPECT_EQ(p.error(), make_error_code(GetParam().code)) << GetParam().what;
  EXPECT_EQ(why, GetParam().why) << GetParam().what;
}

INSTANTIATE_TEST_SUITE_P(
    Each, EdsNodeProfileRefusal,
    ::testing::Values(
        Refusal{"unknown",
                {{"Input filtr", 1}},
                Errc::kMalformed,
                "parameters: the EDS has no parameter \"Input filtr\" (did you mean \"Input "
                "filter\"?)"},
        Refusal{"read only",
                {{"Analog input 1", 1}},
                Errc::kMalformed,
                "parameters: Param2 \"Analog input 1\" is read only"},
        Refusal{"beyond the limits",
                {{"Input filter", 101}},
                Errc::kOutOfRange,
                "parameters: Param1 \"Input filter\": 101 is outside the EDS's limits 0..100"},
        Refusal{"not an integer",
                {{"Input filter", 2.5}},
                Errc::kOutOfRange,
                "parameters: Param1 \"Input filter\": 2.5 is not a UINT value"},
        Refusal{"also in the safe state",
                {{"Output idle action", 1}},
                Errc::kMalformed,
                "safe_state_parameters: Param8 \"Output idle action\" is given twice"}));

TEST(EdsNodeProfile, AConnectionTheEdsDoesNotOfferIsRefused) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  EdsNode n = polled();
  std::string why;
  n.connection = ConnectionKind::kStrobe;
  EXPECT_EQ(profile_of(f, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why,
            "the EDS offers no bit-strobe connection (it offers: poll, change of state, cyclic)");
  // The valve manifold offers bit-strobe, and no change of state.
  const EdsFile manifold = test::example_eds(test::kValveManifoldEds);
  EdsNode m = polled();
  m.connection = ConnectionKind::kChangeOfState;
  EXPECT_EQ(profile_of(manifold, m, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why, "the EDS offers no change of state connection (it offers: poll, bit-strobe)");
}

TEST(EdsNodeProfile, ABitStrobedNodeAnswersWithItsStrobeInputOnBothConnections) {
  const EdsFile manifold = test::example_eds(test::kValveManifoldEds);
  EdsNode m = polled();
  m.connection = ConnectionKind::kStrobe;
  std::string why;
  auto p = profile_of(manifold, m, &why);
  ASSERT_TRUE(p.ok()) << why;
  ASSERT_TRUE(p->input_connection.has_value());
  EXPECT_EQ(p->input_connection->kind, devicenet::InputKind::kBitStrobe);
  // Input2 (Assembly 102, the status byte) on Connection 3 and on the poll
  // connection; Output1 (Assembly 151, the coils) polled.
  const std::vector<std::uint8_t> assembly102{0x20, 0x04, 0x24, 0x66, 0x30, 0x03};
  EXPECT_EQ(p->input_connection->produced_path, assembly102);
  EXPECT_EQ(p->produced_path, assembly102);
  EXPECT_EQ(p->input_connection->produced_size, 1u);
  EXPECT_EQ(p->produced_size, 1u);
  EXPECT_EQ(p->consumed_size, 2u);
  EXPECT_FALSE(p->input_connection->inhibit.has_value());
}

TEST(EdsNodeProfile, ABitStrobeThatConsumesAnOutputOrAnswersInMoreThanOneFrameIsRefused) {
  const std::string device =
      "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n";
  auto consumes = parse(device +
                        "[IO_Info]\nPollInfo = 1, 1, 1;\nStrobeInfo = 2, 1, 1;\n"
                        "Input1 = 1, 0, 3, \"in\", 6, \"20 04 24 64 30 03\", \"\";\n"
                        "Output1 = 1, 0, 3, \"out\", 6, \"20 04 24 96 30 03\", \"\";\n");
  ASSERT_TRUE(consumes.file.has_value());
  EdsNode n;
  n.connection = ConnectionKind::kStrobe;
  std::string why;
  EXPECT_EQ(profile_of(*consumes.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why,
            "the EDS's bit-strobe connection consumes Output1: dnbridge's master sends every "
            "strobe bit as 0, and takes outputs on the poll connection only");
  auto large = parse(device +
                     "[IO_Info]\nPollInfo = 1, 1, 0;\nStrobeInfo = 2, 1, 0;\n"
                     "Input1 = 9, 0, 3, \"in\", 6, \"20 04 24 64 30 03\", \"\";\n");
  ASSERT_TRUE(large.file.has_value());
  EXPECT_EQ(profile_of(*large.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why, "the EDS's bit-strobe input is 9 bytes: a bit-strobe response carries at most 8");
  // An input the poll connection may not carry: the node is polled for the
  // same input beside its bit-strobe connection.
  auto strobe_only = parse(device +
                           "[IO_Info]\nPollInfo = 1, 1, 0;\nStrobeInfo = 2, 2, 0;\n"
                           "Input1 = 1, 0, 1, \"in\", 6, \"20 04 24 64 30 03\", \"\";\n"
                           "Input2 = 1, 0, 2, \"status\", 6, \"20 04 24 65 30 03\", \"\";\n");
  ASSERT_TRUE(strobe_only.file.has_value());
  EXPECT_EQ(profile_of(*strobe_only.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why,
            "Input2 (\"status\") is carried by bit-strobe only (EDS line 7): a node on "
            "bit-strobe is polled for the same input beside it");
}

TEST(EdsNodeProfile, ChangeOfStateNeedsThePollConnectionBesideItForTheOutputs) {
  auto parsed = parse(
      "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
      "[IO_Info]\nCOSInfo = 4, 1, 0;\n"
      "Input1 = 1, 0, 4, \"in\", 6, \"20 04 24 64 30 03\", \"\";\n");
  ASSERT_TRUE(parsed.file.has_value());
  EdsNode n;
  n.connection = ConnectionKind::kChangeOfState;
  std::string why;
  EXPECT_EQ(profile_of(*parsed.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why,
            "the EDS offers no poll connection (it offers: change of state): a node on change "
            "of state has its outputs and keeps its connections on a poll connection beside it");
}

TEST(EdsNodeProfile, AChangeOfStateNodeProducesTheInputsOnInstance4AndIsPolledForItsOutputs) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  EdsNode n = polled();
  n.connection = ConnectionKind::kChangeOfState;
  n.heartbeat = milliseconds(250);
  n.inhibit = milliseconds(15);
  n.acknowledged = false;
  std::string why;
  auto p = profile_of(f, n, &why);
  ASSERT_TRUE(p.ok()) << why;
  ASSERT_TRUE(p->input_connection.has_value());
  EXPECT_FALSE(p->input_connection->kind == devicenet::InputKind::kCyclic);
  EXPECT_FALSE(p->input_connection->acknowledged);
  EXPECT_EQ(p->input_connection->expected_packet_rate, milliseconds(250));
  EXPECT_EQ(p->input_connection->inhibit, milliseconds(15));
  // Input1 (Assembly 100) on both connections; Output1 (Assembly 150) polled.
  const std::vector<std::uint8_t> assembly100{0x20, 0x04, 0x24, 0x64, 0x30, 0x03};
  EXPECT_EQ(p->input_connection->produced_path, assembly100);
  EXPECT_EQ(p->produced_path, assembly100);
  EXPECT_EQ(p->input_connection->produced_size, 4u);
  EXPECT_EQ(p->consumed_size, 2u);

  n.connection = ConnectionKind::kCyclic;
  p = profile_of(f, n, &why);
  ASSERT_TRUE(p.ok()) << why;
  EXPECT_TRUE(p->input_connection->kind == devicenet::InputKind::kCyclic);
  EXPECT_FALSE(p->input_connection->inhibit.has_value());  // a cyclic connection has none
}

TEST(EdsNodeProfile, AParameterWithoutALinkPathOrOfAStringTypeIsNotSet) {
  auto parsed = parse(
      "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
      "[IO_Info]\nPollInfo = 1, 1, 0;\n"
      "Input1 = 1, 0, 1, \"in\", 0, \"\", \"\";\n"
      "[Params]\n"
      "Param1 = 0, 0, , 0, 0xC6, 1, \"unlinked\", \"\", \"\", 0, 9, 0;\n"
      "Param2 = 0, 6, \"20 0F 24 02 30 01\", 0, 0xDA, 0, \"label\", \"\", \"\";\n");
  ASSERT_TRUE(parsed.file.has_value());
  EdsNode n;
  n.parameters = {{"unlinked", 1}};
  std::string why;
  EXPECT_EQ(profile_of(*parsed.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why,
            "parameters: Param1 \"unlinked\" has no link path to an attribute (its link path: "
            "none)");
  n.parameters = {{"label", 1}};
  EXPECT_EQ(profile_of(*parsed.file, n, &why).error(), make_error_code(Errc::kUnsupported));
  EXPECT_EQ(why, "parameters: Param2 \"label\" is a SHORT_STRING: only numbers are set");
  // Inputs only: no safe state is needed.
  n.parameters.clear();
  auto p = profile_of(*parsed.file, n, &why);
  ASSERT_TRUE(p.ok()) << why;
  EXPECT_EQ(p->consumed_size, 0u);
  EXPECT_TRUE(p->consumed_path.empty());
  EXPECT_EQ(p->format_description, "input 1 B \"in\", no output");
}

TEST(EdsNodeProfile, AParameterNameSeveralParametersHaveMustBeGivenAsParamN) {
  auto parsed = parse(
      "[Device]\nVendCode = 1; ProdType = 0; ProdCode = 2; MajRev = 1; MinRev = 1;\n"
      "[IO_Info]\nPollInfo = 1, 1, 0;\n"
      "Input1 = 1, 0, 1, \"in\", 0, \"\", \"\";\n"
      "[Params]\n"
      "Param1 = 0, 6, \"20 09 24 01 30 05\", 0, 0xC6, 1, \"Fault action\", \"\", \"\", 0, 1, 0;\n"
      "Param2 = 0, 6, \"20 09 24 02 30 05\", 0, 0xC6, 1, \"Fault action\", \"\", \"\", 0, 1, 0;\n");
  ASSERT_TRUE(parsed.file.has_value());
  EdsNode n;
  n.parameters = {{"fault action", 1}};
  std::string why;
  EXPECT_EQ(profile_of(*parsed.file, n, &why).error(), make_error_code(Errc::kMalformed));
  EXPECT_EQ(why,
            "parameters: \"fault action\" names 2 parameters (Param1, Param2): name one as "
            "ParamN");
  n.parameters = {{"Param1", 1}, {"param2", 1}};
  auto p = profile_of(*parsed.file, n, &why);
  ASSERT_TRUE(p.ok()) << why;
  ASSERT_EQ(p->settings.size(), 2u);
  EXPECT_EQ(p->settings[1].instance_id, 2);
  // Both given: nothing of the safe state is left to the device.
  EXPECT_TRUE(safe_state_left_to_device(*parsed.file, n).empty());
  n.parameters = {{"Param1", 1}};
  const auto left = safe_state_left_to_device(*parsed.file, n);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0]->number, 2u);
}

TEST(EdsNodeProfile, TheSafeStateParametersNotGivenAreTheDevicesOwn) {
  const EdsFile f = test::example_eds(test::kIoBlockEds);
  EdsNode n = polled();
  EXPECT_TRUE(safe_state_left_to_device(f, n).empty());
  n.safe_state = {{"Output idle action", 0}};
  std::vector<unsigned> left;
  for (const Param* p : safe_state_left_to_device(f, n)) left.push_back(p->number);
  EXPECT_EQ(left, (std::vector<unsigned>{6, 7, 9}));
}

}  // namespace
}  // namespace dnbridge::profiles::eds
