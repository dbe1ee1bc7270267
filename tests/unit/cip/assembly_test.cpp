// The Assembly object's member list (attribute 2) as a device sends it:
// per member its size in bits, its path size and its path; empty paths are
// padding; paths that are not logical are kept as bytes.
#include "bridge/cip/assembly.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace dnbridge::cip {
namespace {

// 16 bits of Parameter 2's value, 8 bits of padding, 8 bits named by an
// ANSI symbolic segment ("ABC"), which is not a logical path.
const std::vector<std::uint8_t> kList = {
    0x10, 0x00, 0x06, 0x00, 0x20, 0x0F, 0x24, 0x02, 0x30, 0x01,  // 16 bits, 6-byte path
    0x08, 0x00, 0x00, 0x00,                                      // 8 bits, padding
    0x08, 0x00, 0x06, 0x00, 0x91, 0x03, 0x41, 0x42, 0x43, 0x00,  // 8 bits, symbolic
};

TEST(AssemblyMemberList, DecodesSizesPathsAndPadding) {
  auto members = decode_member_list(Bytes(kList.data(), kList.size()));
  ASSERT_TRUE(members.ok()) << members.error().message();
  ASSERT_EQ(members->size(), 3u);
  const auto& m = *members;
  EXPECT_EQ(m[0].bits, 16);
  ASSERT_TRUE(m[0].path.has_value());
  EXPECT_EQ(*m[0].path, (EPath{0x0F, 2, std::nullopt, 1}));
  EXPECT_EQ(describe(m[0]), "16 bits: class 0x0F instance 0x02 attribute 0x01");
  EXPECT_TRUE(m[1].padding());
  EXPECT_EQ(describe(m[1]), "8 bits: padding");
  EXPECT_FALSE(m[2].padding());
  EXPECT_FALSE(m[2].path.has_value());
  EXPECT_EQ(describe(m[2]), "8 bits: path 91 03 41 42 43 00");
  EXPECT_EQ(member_bits(m), 32u);
  EXPECT_EQ(encode_member_list(m), kList);
}

TEST(AssemblyMemberList, AnEmptyListHasNoMembers) {
  auto members = decode_member_list(Bytes{});
  ASSERT_TRUE(members.ok());
  EXPECT_TRUE(members->empty());
}

TEST(AssemblyMemberList, AMemberCutOffIsTruncated) {
  for (std::size_t cut : {1u, 3u, 5u, 9u, 13u, 23u}) {
    auto members = decode_member_list(Bytes(kList.data(), cut));
    ASSERT_FALSE(members.ok()) << cut;
    EXPECT_EQ(members.error(), make_error_code(Errc::kTruncated)) << cut;
  }
}

}  // namespace
}  // namespace dnbridge::cip
