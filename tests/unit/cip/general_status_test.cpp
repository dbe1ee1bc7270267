#include "bridge/cip/general_status.hpp"

#include <gtest/gtest.h>

namespace dnbridge::cip {
namespace {

TEST(GeneralStatusTest, EveryCodeOfTheTableIsNamed) {
  // bridge/PROTOCOL.md §4: 0x00..0x2A and 0x2C.
  for (unsigned code = 0; code <= 0x2A; ++code) {
    EXPECT_TRUE(is_known(static_cast<std::uint8_t>(code))) << std::hex << code;
  }
  EXPECT_TRUE(is_known(0x2C));
  EXPECT_FALSE(is_known(0x2B));
  EXPECT_FALSE(is_known(0x2D));
  EXPECT_FALSE(is_known(0xFF));
  EXPECT_EQ(to_string(GeneralStatus::kObjectStateConflict), "object state conflict");
  EXPECT_EQ(to_string(GeneralStatus::kGroup2OnlyServerFailure),
            "Group 2 only server general failure");
}

}  // namespace
}  // namespace dnbridge::cip
