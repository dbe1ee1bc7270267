#pragma once
// The rack file's keys, in one table: where each may stand, its type, range
// and default, what a reload does with it, one line of documentation.
//
// The reader (config*.cpp) asks for no key the table does not list for the
// table it reads (toml_config::TableReader::allow_only throws on such a
// request, so a test that reaches it fails); a key written where it may not
// stand, or on a node of another profile, is reported with what the table
// says of it; dnbridge.toml(5)'s key reference is generated from it at build
// time (config_keys_roff).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dnbridge::daemon {

// The limits the integer keys are read with (milliseconds for keys named
// *_ms). DeviceNet expected packet rates are UINT milliseconds (Connection
// object attribute 9), and a poll period is bounded by its expected packet
// rate.
constexpr std::int64_t kMaxPacketRateMs = 0xFFFF;
constexpr std::int64_t kMaxPublishPeriodMs = 3'600'000;
constexpr std::int64_t kMaxPollBatchMs = 1000;
constexpr std::int64_t kMaxResponseTimeoutMs =
    60'000;  // cut to a quarter of each node's poll period
// A command refresh shorter than a DDS write's round trip under load would
// idle a healthy commander's pumps; longer than ten minutes is no bound.
constexpr std::int64_t kMinCommandRefreshMs = 50;
constexpr std::int64_t kMaxCommandRefreshMs = 600'000;
// A lease shorter than this would have a commander lose its pumps on any
// hiccup of its host; longer than ten minutes is no bound.
constexpr std::int64_t kMinCommanderLeaseMs = 100;
constexpr std::int64_t kMaxCommanderLeaseMs = 600'000;
// RTPS maps domain IDs to UDP ports; with the standard port parameters the
// highest that fits is 232.
constexpr std::int64_t kMaxDomainId = 232;

// The tables of a rack file a key stands in.
enum class KeyPlace : std::uint8_t {
  kTop,             // the top level
  kExplicitPolicy,  // [explicit_policy]
  kMetrics,         // [metrics]
  kSecurity,        // [security]
  kPort,            // [[port]]
  kNode,            // [[port.node]], and [defaults] where `defaults` says so
  kIo,              // a node's io = { ... }
  kIdentity,        // a node's identity = { ... }
  kParameter,       // one { name, value } of an EDS node's parameters or safe_state_parameters
};

// The profiles a node key is for.
enum ProfileSet : std::uint8_t {
  kCdn127Nodes = 1,
  kEdsNodes = 2,
  kEveryProfile = kCdn127Nodes | kEdsNodes,
};

// What `systemctl reload` (SIGHUP, dnbctl reload) does with a changed value.
enum class OnReload : std::uint8_t {
  kApplied,       // applied at once; nodes keep running
  kReconfigured,  // the node is released and configured again
  kRestart,       // stays as it is until the bridge restarts (logged)
  kByItsKeys,     // a table of keys of their own: each says
};

// An integer key's bounds (min..max, the reader's), and what else the
// value must be, in words: "unique on the port", "\"idle\" or \"hold\"".
struct KeyRange {
  std::int64_t min = 0;
  std::int64_t max = -1;  // below min: no bounds
  std::string_view text;
  constexpr bool bounded() const noexcept { return min <= max; }
};
// A value's range in words only: a string's choices, a non-integer's.
constexpr KeyRange words(std::string_view text) noexcept { return {0, -1, text}; }

struct ConfigKey {
  std::string_view name;
  KeyPlace place;
  std::string_view type;  // "integer, ms", "string", "table"
  KeyRange range;
  std::string_view fallback;  // the default, "required", or "none"
  OnReload reload;
  std::string_view doc;  // one line
  // Node keys only: the profiles whose nodes take it, and whether
  // [defaults] may hold it for every node of those profiles.
  std::uint8_t profiles = kEveryProfile;
  bool in_defaults = false;
};

// Every key, grouped by place, in the order the reference shows them.
std::span<const ConfigKey> config_keys() noexcept;

// The key `name` at `place`, or null.
const ConfigKey* config_key(KeyPlace place, std::string_view name) noexcept;

// The bounds of the integer key `name` at `place`, which the reader reads it
// with; std::logic_error when the table gives it none.
KeyRange bounds_of(KeyPlace place, std::string_view name);

// The names of the keys at `place` (for [defaults]: the node keys it may
// hold), for TableReader::allow_only.
std::vector<std::string_view> key_names(KeyPlace place);
std::vector<std::string_view> defaults_key_names();

// Why `key`, unknown where it stands, belongs elsewhere ("mac stands in a
// [[port.node]] table only"), from the table; empty when no table holds it.
std::string misplaced_key(KeyPlace place, bool in_defaults, std::string_view key);

// Why a node of `profile` (kCdn127Nodes or kEdsNodes) does not take `key`;
// empty when it does, or when `key` is no node key.
std::string other_profile_key(std::uint8_t profile, std::string_view key);

// The node keys a node of `profile` does not take: the keys to refuse on it.
std::vector<std::string_view> keys_of_other_profiles(std::uint8_t profile);

// The KEYS section of dnbridge.toml(5), in roff.
std::string key_reference_roff();

}  // namespace dnbridge::daemon
