// The rack file's key table against the reader and the man page: every key
// of the table is read where the table puts it, a key where it does not
// stand is told where it does, and the installed dnbridge.toml(5) documents
// every key.
#include "adapters/daemon/config_keys.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "adapters/daemon/config.hpp"
#include "bridge/rack/explicit_policy.hpp"
#include "config_text.hpp"

namespace dnbridge::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

using config_test::problems;

// No key takes a date-time: whoever reads KEY = this says what it must be.
constexpr std::string_view kNoKeysValue = "1979-05-27T07:32:00Z";

std::string line(std::string_view key, std::string_view value) {
  return fmt::format("{} = {}\n", key, value);
}

// `text` without the line that sets `key` (lines of "key = value").
std::string without(std::string_view key, std::string text) {
  std::istringstream in(text);
  std::string out, l;
  while (std::getline(in, l)) {
    if (l.starts_with(fmt::format("{} = ", key))) continue;
    out += l + "\n";
  }
  return out;
}

constexpr std::string_view kPortKeys =
    "name = \"A\"\ninterface = \"simulated\"\nbitrate = 500000\n";
constexpr std::string_view kEdsNodeKeys =
    "mac = 20\nname = \"io-1\"\nprofile = \"eds\"\neds = \"dnbridge-example-io-block.eds\"\n"
    "safe_state = \"device\"\n";
constexpr std::string_view kCdn127NodeKeys = "mac = 1\nname = \"p\"\n";

// A rack with `key` set to `value` where the table puts it, on a node of
// `profile` for node keys (in [defaults] when `in_defaults`).
std::string rack_with(const ConfigKey& k, std::uint8_t profile, bool in_defaults,
                      const std::string& value = std::string(kNoKeysValue)) {
  const std::string node_keys(profile == kEdsNodes ? kEdsNodeKeys : kCdn127NodeKeys);
  std::string top = "rack = \"r\"\n";
  std::string port = "[[port]]\n" + std::string(kPortKeys);
  std::string node = "[[port.node]]\n" + node_keys;
  switch (k.place) {
    case KeyPlace::kTop:
      top = without(k.name, top) + line(k.name, value);
      if (k.name == "port") port = node = "";
      break;
    case KeyPlace::kExplicitPolicy:
      top += "[explicit_policy]\n" + line(k.name, value);
      break;
    case KeyPlace::kMetrics:
      top += "[metrics]\n" + line(k.name, value);
      break;
    case KeyPlace::kSecurity:
      top += "[security]\n" + line(k.name, value);
      break;
    case KeyPlace::kPort:
      port = "[[port]]\n" + without(k.name, std::string(kPortKeys)) + line(k.name, value);
      if (k.name == "node") node = "";
      break;
    case KeyPlace::kNode:
      if (in_defaults) {
        top += "[defaults]\n" + line(k.name, value);
      } else {
        node = "[[port.node]]\n" + without(k.name, node_keys) + line(k.name, value);
      }
      break;
    case KeyPlace::kIo:
      node += fmt::format("io = {{ {} = {} }}\n", k.name, value);
      break;
    case KeyPlace::kIdentity: {
      std::string fields;
      for (std::string_view f : {"vendor_id", "product_type", "product_code"}) {
        fields += fmt::format("{}{} = {}", fields.empty() ? "" : ", ", f,
                              f == k.name ? value : std::string("1"));
      }
      node += fmt::format("identity = {{ {} }}\n", fields);
      break;
    }
    case KeyPlace::kParameter: {
      node = "[[port.node]]\n" + std::string(kEdsNodeKeys);
      const std::string name = k.name == "name" ? value : std::string("\"Input filter\"");
      const std::string v = k.name == "value" ? value : std::string("5");
      node += fmt::format("parameters = [ {{ name = {}, value = {} }} ]\n", name, v);
      break;
    }
  }
  return top + port + node;
}

TEST(ConfigKeys, EveryKeyOfTheTableIsReadWhereTheTablePutsIt) {
  for (const ConfigKey& k : config_keys()) {
    std::vector<std::pair<std::uint8_t, bool>> cases;  // profile, in [defaults]
    if (k.place != KeyPlace::kNode) {
      cases.push_back({kCdn127Nodes, false});
    } else {
      for (std::uint8_t p : {kCdn127Nodes, kEdsNodes}) {
        if ((k.profiles & p) == 0) continue;
        // The EDS node's profile key is the one that makes it an EDS node.
        if (p == kEdsNodes && k.name == "profile") continue;
        cases.push_back({p, false});
      }
      if (k.in_defaults) cases.push_back({kCdn127Nodes, true});
    }
    for (const auto& [profile, in_defaults] : cases) {
      const std::string text = rack_with(k, profile, in_defaults);
      SCOPED_TRACE(text);
      const std::string p = problems(text);
      // At the line the value is on, naming the key.
      std::size_t line = 1;
      for (std::size_t i = 0; i < text.find(kNoKeysValue); ++i) line += text[i] == '\n';
      std::istringstream lines(p);
      std::string at_line, l;
      while (std::getline(lines, l)) {
        if (l.starts_with(fmt::format("t.toml:{}:", line))) at_line += l + "\n";
      }
      EXPECT_THAT(at_line, HasSubstr(std::string(k.name)));
      EXPECT_THAT(p, Not(HasSubstr("unknown key")));
      EXPECT_THAT(p, Not(HasSubstr(" stands in ")));
    }
  }
}

// The bounds the table gives are the reader's: its least and greatest
// values are taken, one beyond each is out of range. A node key is tried in
// [defaults] where it may stand, read there as it stands, without the
// checks against the node's other keys.
TEST(ConfigKeys, TheReaderTakesEachBoundedKeyWithinTheTablesBoundsAndNoFurther) {
  for (const ConfigKey& k : config_keys()) {
    // Every integer key has its bounds in the table, or its choices.
    if (k.type.starts_with("integer")) {
      EXPECT_TRUE(k.range.bounded() || !k.range.text.empty()) << k.name;
    }
    if (!k.range.bounded()) continue;
    const bool in_defaults = k.place == KeyPlace::kNode && k.in_defaults;
    const std::uint8_t profile = (k.profiles & kCdn127Nodes) != 0 ? kCdn127Nodes : kEdsNodes;
    // The problems about `key = v`.
    const auto about = [&](std::int64_t v) {
      const std::string text = rack_with(k, profile, in_defaults, std::to_string(v));
      std::istringstream lines(problems(text));
      std::string found, l;
      const std::string said = fmt::format("{} = {}", k.name, v);
      while (std::getline(lines, l)) {
        const auto at = l.find(said);
        if (at == std::string::npos) continue;
        const std::size_t end = at + said.size();
        if (end == l.size() || !std::isdigit(static_cast<unsigned char>(l[end]))) found += l + "\n";
      }
      return found;
    };
    const auto refused = ::testing::AnyOf(HasSubstr("out of range"), HasSubstr("is more than"));
    for (std::int64_t v : {k.range.min, k.range.max}) {
      EXPECT_THAT(about(v), Not(refused)) << k.name << " = " << v;
    }
    for (std::int64_t v : {k.range.min - 1, k.range.max + 1}) {
      EXPECT_THAT(about(v), refused) << k.name << " = " << v;
    }
  }
}

TEST(ConfigKeys, TheExplicitPolicysKeysAreThePolicysOwn) {
  std::set<std::string_view> policy, table;
  for (std::size_t i = 0; i < rack::kGuardedRequestKinds; ++i) {
    policy.insert(rack::policy_key(static_cast<rack::GuardedRequest>(i)));
  }
  for (std::string_view k : key_names(KeyPlace::kExplicitPolicy)) table.insert(k);
  EXPECT_EQ(policy, table);
}

TEST(ConfigKeys, AKeyWhereItDoesNotStandIsToldWhereItStands) {
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "interface = \"can0\"\n"
                     "[[port]]\n"
                     "name = \"A\"\n"
                     "interface = \"simulated\"\n"
                     "bitrate = 500000\n"
                     "poll_period_ms = 20\n"
                     "[[port.node]]\n"
                     "mac = 1\n"
                     "name = \"p\"\n"
                     "bus_off_recovery = \"report\"\n"),
            "t.toml:2:1: interface is a port key: it stands in a [[port]] table, not at the top "
            "level\n"
            "t.toml:7:1: poll_period_ms is a node key: it stands in [defaults] or a [[port.node]] "
            "table\n"
            "t.toml:11:1: bus_off_recovery is a port key: it stands in the [[port]] table, before "
            "its [[port.node]] tables");
  EXPECT_EQ(problems("rack = \"r\"\n"
                     "mac = 3\n"
                     "name = \"x\"\n"
                     "[defaults]\n"
                     "poll_batch_ms = 3\n"
                     "[[port]]\n" +
                     std::string(kPortKeys)),
            "t.toml:2:1: mac is a node key: it stands in a [[port.node]] table only, not at the "
            "top level\n"
            "t.toml:3:1: name stands in a [[port]] or [[port.node]] table, not at the top level\n"
            "t.toml:5:1: poll_batch_ms is a port key: it stands in a [[port]] table, not in "
            "[defaults]");
  EXPECT_THAT(problems("rack = \"r\"\n"
                       "[defaults]\n"
                       "serial = 3\n"
                       "[[port]]\n" +
                       std::string(kPortKeys)),
              HasSubstr("t.toml:3:1: serial stands in a [[port.node]] table only, not in "
                        "[defaults]"));
}

TEST(ConfigKeys, AKeyOfAnotherProfileIsRefusedWithItsProfile) {
  EXPECT_EQ(keys_of_other_profiles(kCdn127Nodes),
            (std::vector<std::string_view>{"eds", "connection", "heartbeat_ms", "inhibit_ms",
                                           "acknowledged", "parameters", "safe_state_parameters"}));
  EXPECT_EQ(other_profile_key(kCdn127Nodes, "heartbeat_ms"),
            "heartbeat_ms is for profile = \"eds\" nodes");
  EXPECT_EQ(other_profile_key(kEdsNodes, "pump_on_fault"),
            "pump_on_fault is a CDN127 setting: this node has profile = \"eds\"");
  EXPECT_EQ(other_profile_key(kEdsNodes, "poll_period_ms"), "");
}

// The man page as the package installs it (deploy/packaging.cmake renders it).
TEST(ConfigKeys, TheInstalledManPageDocumentsEveryKey) {
  std::ifstream in(DNBRIDGE_TOML_MAN_PAGE);
  ASSERT_TRUE(in) << DNBRIDGE_TOML_MAN_PAGE;
  std::stringstream text;
  text << in.rdbuf();
  const std::string page = text.str();
  const auto keys_at = page.find(".SH KEYS");
  ASSERT_NE(keys_at, std::string::npos);
  const std::string keys = page.substr(keys_at, page.find("\n.SH ", keys_at + 1) - keys_at);
  for (const ConfigKey& k : config_keys()) {
    std::string roff_name;
    for (char c : k.name) roff_name += c == '-' ? std::string("\\-") : std::string(1, c);
    EXPECT_THAT(keys, HasSubstr(fmt::format(".B {}\n", roff_name))) << k.name;
  }
}

}  // namespace
}  // namespace dnbridge::daemon
