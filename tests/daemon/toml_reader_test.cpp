// The TOML kit every configuration is read with (adapters/toml_config/reader.hpp):
// the keys a table may hold are the keys its reader asked for, within the
// table of its keys where it is held to one.
#include <gtest/gtest.h>

#include <stdexcept>

#include "adapters/toml_config/reader.hpp"

namespace dnbridge::toml_config {
namespace {

TEST(TomlReader, AKeyNoReaderAskedForIsUnknownWithTheClosestAskedAsAHint) {
  Problems p("t.toml");
  const auto root = parse("pollperiod_ms = 5\nname = \"a\"\n", p);
  ASSERT_TRUE(root.has_value());
  {
    TableReader t(*root, "[x]", p);
    ASSERT_NE(t.get("name"), nullptr);
    EXPECT_EQ(t.get("poll_period_ms"), nullptr);  // asked for, absent: declared all the same
    EXPECT_EQ(t.get("epr_ms"), nullptr);
  }
  EXPECT_EQ(
      p.errors(),
      (std::vector<std::string>{
          "t.toml:1:1: unknown key 'pollperiod_ms' in [x] (did you mean 'poll_period_ms'?)"}));
}

TEST(TomlReader, AReaderHeldToItsKeysTableAsksForNoOtherAndExplainsWhatStandsElsewhere) {
  Problems p("t.toml");
  const auto root = parse("pollperiod_ms = 5\nmac = 3\nname = \"a\"\n", p);
  ASSERT_TRUE(root.has_value());
  {
    TableReader t(*root, "[x]", p);
    t.allow_only({"name", "poll_period_ms"}, [](std::string_view key) {
      return key == "mac" ? std::string("mac stands elsewhere") : std::string();
    });
    ASSERT_NE(t.get("name"), nullptr);
    EXPECT_THROW(t.get("colour"), std::logic_error);
  }
  // The hint comes from the allowed keys, asked for or not.
  EXPECT_EQ(p.errors(),
            (std::vector<std::string>{
                "t.toml:1:1: unknown key 'pollperiod_ms' in [x] (did you mean 'poll_period_ms'?)",
                "t.toml:2:1: mac stands elsewhere"}));
}

TEST(TomlReader, RequiredKeysAndTypedValuesSayWhatIsWrongWhere) {
  Problems p("t.toml");
  const auto root = parse("a = \"x\"\nb = 70\n", p);
  ASSERT_TRUE(root.has_value());
  TableReader t(*root, "the top level", p);
  EXPECT_EQ(t.require("c"), nullptr);
  EXPECT_FALSE(read_bool(*t.get("a"), "a", p).has_value());
  EXPECT_FALSE(read_ms(*t.get("b"), "b", 1, 60, p).has_value());
  EXPECT_EQ(read_int_as<int>(*t.get("b"), "b", {0, 100}, p), 70);
  t.finish();
  EXPECT_EQ(p.errors(), (std::vector<std::string>{
                            "t.toml:1:1: missing required key 'c' in the top level",
                            "t.toml:1:5: a must be true or false, not a string",
                            "t.toml:2:5: b = 70 is out of range (1..60 ms)",
                        }));
}

TEST(TomlReader, AProblemReportedTwiceAtOnePlaceIsKeptOnce) {
  Problems p("t.toml");
  const auto root = parse("[defaults]\nx = 1\n", p);
  ASSERT_TRUE(root.has_value());
  const toml::node& x = *root->at_path("defaults.x").node();
  for (int node = 0; node < 3; ++node) (void)read_string(x, "x", p);
  p.warning(x.source(), "said once");
  p.warning(x.source(), "said once");
  EXPECT_EQ(p.errors(),
            (std::vector<std::string>{"t.toml:2:5: x must be a string, not an integer"}));
  EXPECT_EQ(p.warnings(), (std::vector<std::string>{"t.toml:2:5: said once"}));
}

TEST(TomlReader, ASyntaxErrorIsAProblemWithItsPlace) {
  Problems p("t.toml");
  EXPECT_FALSE(parse("a = \n", p).has_value());
  ASSERT_EQ(p.errors().size(), 1u);
  EXPECT_EQ(p.errors()[0].rfind("t.toml:1:", 0), 0u) << p.errors()[0];
}

}  // namespace
}  // namespace dnbridge::toml_config
