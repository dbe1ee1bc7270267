#include "bridge/common/closest.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string_view>

namespace dnbridge {
namespace {

TEST(Closest, EditDistance) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("list", "list"), 0u);
  EXPECT_EQ(edit_distance("lst", "list"), 1u);   // a letter missing
  EXPECT_EQ(edit_distance("lsit", "list"), 2u);  // two letters swapped
  EXPECT_EQ(edit_distance("pump", "racks"), 5u);
  EXPECT_EQ(edit_distance("", "show"), 4u);
}

TEST(Closest, TheNearestWithinTheLimit) {
  constexpr std::array<std::string_view, 4> commands{"list", "racks", "show", "set"};
  EXPECT_EQ(closest("lst", commands), "list");
  EXPECT_EQ(closest("shw", commands), "show");
  EXPECT_EQ(closest("frobnicate", commands), std::nullopt);
  EXPECT_EQ(closest("list", commands), std::nullopt);  // known: nothing to suggest
  EXPECT_EQ(closest("rcks", commands, 0), std::nullopt);
  EXPECT_EQ(closest("rcks", commands, 1), "racks");
}

}  // namespace
}  // namespace dnbridge
