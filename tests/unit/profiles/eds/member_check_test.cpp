// A device's assembly member list against its EDS: agreement, and each kind
// of difference said with the member, both sides and the assembly.
#include "bridge/profiles/eds/member_check.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/support/example_eds.hpp"

namespace dnbridge::profiles::eds {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

EdsFile io_block() { return test::example_eds(test::kIoBlockEds); }

cip::AssemblyMember member(std::uint16_t bits, std::vector<std::uint8_t> path) {
  cip::AssemblyMember m;
  m.bits = bits;
  m.path_bytes = std::move(path);
  if (!m.path_bytes.empty()) {
    if (auto p = cip::decode_epath(Bytes(m.path_bytes.data(), m.path_bytes.size()))) m.path = *p;
  }
  return m;
}

// Assem100 of the example as a device that agrees reports it: the link
// paths of Param3, Param5 and Param2.
std::vector<cip::AssemblyMember> agreeing() {
  return {member(8, {0x20, 0x0F, 0x24, 0x03, 0x30, 0x01}),
          member(8, {0x20, 0x0F, 0x24, 0x05, 0x30, 0x01}),
          member(16, {0x20, 0x0F, 0x24, 0x02, 0x30, 0x01})};
}

TEST(EdsMemberCheck, AnAgreeingDeviceHasNoDifferences) {
  const EdsFile f = io_block();
  ASSERT_FALSE(f.assemblies.empty());
  EXPECT_THAT(member_differences(f, f.assemblies[0], agreeing()), IsEmpty());
}

TEST(EdsMemberCheck, ADifferentPathIsSaidWithBothSides) {
  const EdsFile f = io_block();
  auto reported = agreeing();
  reported[1] = member(8, {0x20, 0x08, 0x24, 0x02, 0x30, 0x03});
  EXPECT_THAT(member_differences(f, f.assemblies[0], reported),
              ElementsAre("member 2: class 0x08 instance 0x02 attribute 0x03 on the device, "
                          "Param5 (Module status), class 0x0F instance 0x05 attribute 0x01 in "
                          "the EDS"));
}

TEST(EdsMemberCheck, SizesCountsAndPaddingDifferencesAreEachSaid) {
  const EdsFile f = io_block();
  std::vector<cip::AssemblyMember> reported = {member(8, {0x20, 0x0F, 0x24, 0x03, 0x30, 0x01}),
                                               member(16, {})};
  EXPECT_THAT(member_differences(f, f.assemblies[0], reported),
              ElementsAre("24 bits in all on the device, 32 in the EDS (Assem100)",
                          "2 members on the device, 3 in the EDS (Assem100)",
                          "member 2: 16 bits on the device, 8 in the EDS (Param5 (Module "
                          "status), class 0x0F instance 0x05 attribute 0x01)",
                          "member 2: padding on the device, Param5 (Module status), class 0x0F "
                          "instance 0x05 attribute 0x01 in the EDS"));
}

TEST(EdsMemberCheck, APaddingMemberExpectedIsComparedAsPadding) {
  const EdsFile f = io_block();
  ASSERT_GE(f.assemblies.size(), 2u);
  const Assembly& outputs = f.assemblies[1];  // Param4, then a pad byte
  EXPECT_THAT(member_differences(f, outputs,
                                 {member(8, {0x20, 0x0F, 0x24, 0x04, 0x30, 0x01}), member(8, {})}),
              IsEmpty());
  EXPECT_THAT(member_differences(f, outputs,
                                 {member(8, {0x20, 0x0F, 0x24, 0x04, 0x30, 0x01}),
                                  member(8, {0x20, 0x09, 0x24, 0x01, 0x30, 0x03})}),
              ElementsAre("member 2: class 0x09 instance 0x01 attribute 0x03 on the device, "
                          "padding in the EDS"));
}

}  // namespace
}  // namespace dnbridge::profiles::eds
