// The CIP class list: every class code bridge/cip/objects.hpp defines has
// its name in the one table, so that no reason or log names a class by a
// bare number the bridge itself knows.
#include "bridge/cip/objects.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace dnbridge::cip {
namespace {

// The values of the constants in `namespace class_id { ... }` of the header.
std::set<unsigned> class_ids_in_header() {
  std::ifstream in(std::string(DNBRIDGE_SOURCE_DIR) + "/bridge/cip/objects.hpp");
  std::stringstream text;
  text << in.rdbuf();
  const std::string all = text.str();
  const auto begin = all.find("namespace class_id {");
  const auto end = all.find("}  // namespace class_id", begin);
  EXPECT_NE(begin, std::string::npos);
  EXPECT_NE(end, std::string::npos);
  const std::string block = all.substr(begin, end - begin);
  const std::regex constant(R"(std::uint16_t k\w+ = (0x[0-9A-Fa-f]+);)");
  std::set<unsigned> ids;
  for (std::sregex_iterator it(block.begin(), block.end(), constant), none; it != none; ++it) {
    ids.insert(static_cast<unsigned>(std::stoul((*it)[1].str(), nullptr, 16)));
  }
  return ids;
}

TEST(CipClasses, EveryClassCodeHasItsNameOnce) {
  const std::set<unsigned> ids = class_ids_in_header();
  ASSERT_FALSE(ids.empty());
  EXPECT_EQ(ids.size(), kClasses.size());
  std::set<unsigned> named;
  for (const CipClass& c : kClasses) {
    EXPECT_FALSE(c.name.empty()) << c.id;
    EXPECT_TRUE(named.insert(c.id).second) << c.id << " is in the table twice";
  }
  EXPECT_EQ(named, ids);
  for (unsigned id : ids) {
    EXPECT_FALSE(class_name(static_cast<std::uint16_t>(id)).empty()) << id;
  }
  EXPECT_EQ(class_name(class_id::kParameter), "Parameter");
  EXPECT_EQ(class_name(class_id::kAcknowledgeHandler), "Acknowledge Handler");
  EXPECT_TRUE(class_name(0x64).empty());  // a vendor's class
}

}  // namespace
}  // namespace dnbridge::cip
