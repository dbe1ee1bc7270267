#pragma once
// What the parts of the configuration loader share: the value readers every
// part uses and the layered lookup of node keys (config_values.cpp), the
// limits of timed keys, the readers one part calls in another
// (config_node.cpp, config_node_cdn127.cpp, config_node_eds.cpp,
// config_port.cpp) and what reading one configuration keeps (ReadContext).
#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "adapters/daemon/config.hpp"
#include "adapters/daemon/config_keys.hpp"
#include "adapters/toml_config/reader.hpp"
#include "bridge/common/time.hpp"
#include "bridge/devicenet/wire/mac_id.hpp"
#include "bridge/profiles/cdn127/poll_format.hpp"
#include "bridge/profiles/eds/node_profile.hpp"

namespace dnbridge::daemon::config_detail {

namespace cdn127 = profiles::cdn127;
using devicenet::MacId;
using toml_config::Problems;
using toml_config::TableReader;

// ---------------------------------------------------------------------------
// Values every part reads (config_values.cpp).

// The line of a value, from 1.
std::uint32_t line_of(const toml::source_region& at);

std::optional<MacId> read_mac(const toml::node& n, std::string_view key, Problems& r);

// ---------------------------------------------------------------------------
// Node settings: a node's own keys, else [defaults], else the built-in values.

constexpr std::string_view kProfileCdn127 = "cdn127";
constexpr std::string_view kProfileEds = "eds";

// The node keys of the profiles other than `profile` (kCdn127Nodes,
// kEdsNodes) that the node gives, each refused with its profile.
void refuse_other_profiles_keys(TableReader& node, std::uint8_t profile, Problems& r);

enum class Level { kBuiltIn, kDefaults, kNode };

struct Found {
  const toml::node* value = nullptr;
  Level level = Level::kBuiltIn;
};

// A key is declared in both tables when looked for, found or not: [defaults]
// may hold every key a node's settings are read from.
struct Layers {
  TableReader* node = nullptr;  // null when [defaults] is read alone
  TableReader* defaults = nullptr;

  bool per_node() const noexcept { return node != nullptr; }
  Found find(std::string_view key) const {
    const toml::node* own = node ? node->get(key) : nullptr;
    const toml::node* inherited = defaults ? defaults->get(key) : nullptr;
    if (own) return {own, Level::kNode};
    if (inherited) return {inherited, Level::kDefaults};
    return {};
  }
};

// Where a value another one is compared with came from, for the message.
std::string origin(const Found& f);

constexpr double kAnalogFullScaleVolts = 10.0;

// The integer key `key` at `place`, read within the key table's bounds
// (config_keys.hpp): as a duration in ms, or as T.
std::optional<Duration> read_key_ms(const toml::node& n, KeyPlace place, std::string_view key,
                                    Problems& r);
template <class T>
std::optional<T> read_key_int(const toml::node& n, KeyPlace place, std::string_view key,
                              Problems& r) {
  const KeyRange b = bounds_of(place, key);
  return toml_config::read_int_as<T>(n, key, {b.min, b.max}, r);
}

// command_refresh_ms: 0 (off), or how often a commander must write a
// node's command for it to stay in force (a node's, [defaults]' or a port's).
std::optional<Duration> read_command_refresh(const toml::node& n, Problems& r);

// ---------------------------------------------------------------------------
// A node's keys.

// Every setting a node and [defaults] share (config_node.cpp).
void read_node_settings(const Layers& layers, NodeSettings& s, Problems& r);

// safe_state, the same two choices for every profile: true for "device"
// (the device's own fault and idle actions), false for "configured" (the
// ones the file gives: a CDN127's pump_on_fault ..., an EDS node's
// safe_state_parameters).
std::optional<bool> read_safe_state_source(const toml::node& n, Problems& r);

// A CDN127's own keys (config_node_cdn127.cpp): io, identity, and the safe
// state of its outputs.
std::optional<cdn127::IoConfiguration> read_io(const toml::node& n, Problems& r);
std::optional<devicenet::ExpectedIdentity> read_identity(const toml::node& n, Problems& r);
void read_safe_state(const Layers& layers, NodeSettings& s, Problems& r);

// What reading one configuration keeps besides its problems: where relative
// EDS paths start, and each EDS file read, once.
struct EdsRead {
  std::shared_ptr<const profiles::eds::EdsFile> file;  // null: not usable
  std::uint64_t digest = 0;
  std::uint32_t first_line = 0;  // of the `eds` key that read it
};
struct ReadContext {
  std::filesystem::path base_dir;
  std::map<std::string, EdsRead> eds_files;  // by resolved path
};

// A profile = "eds" node's own keys, its own else [defaults]'; [defaults]
// alone when `layers` has no node (config_node_eds.cpp).
void read_eds_node(const Layers& layers, ReadContext& ctx, NodeSettings& s, Problems& r);

// ---------------------------------------------------------------------------
// A [[port]] table and its [[port.node]] tables (config_port.cpp).

PortConfig read_port(const toml::table& table, const DaemonConfig& rack, TableReader* defaults,
                     ReadContext& ctx, Problems& r);

}  // namespace dnbridge::daemon::config_detail
