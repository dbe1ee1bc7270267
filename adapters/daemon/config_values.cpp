// The values every part of the configuration loader reads (MAC IDs,
// command_refresh_ms) and where a layered node key came from.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>

#include "adapters/daemon/config_internal.hpp"

namespace dnbridge::daemon::config_detail {

using toml_config::IntRange;
using toml_config::read_integer;
using toml_config::read_ms;

std::uint32_t line_of(const toml::source_region& at) {
  return std::max<std::uint32_t>(at.begin.line, 1);
}

namespace {

constexpr IntRange kMacRange{0, MacId::kMax, {}, "a DeviceNet MAC ID is 0..63"};

}  // namespace

std::optional<MacId> read_mac(const toml::node& n, std::string_view key, Problems& r) {
  auto v = read_integer(n, key, kMacRange, r);
  if (!v) return std::nullopt;
  return MacId::from(static_cast<unsigned>(*v));
}

// Where a value another one is compared with came from, for the message.
std::string origin(const Found& f) {
  switch (f.level) {
    case Level::kNode:
      return {};
    case Level::kDefaults:
      return fmt::format(" (from [defaults], line {})", line_of(f.value->source()));
    case Level::kBuiltIn:
      return " (the default)";
  }
  return {};
}

std::optional<Duration> read_key_ms(const toml::node& n, KeyPlace place, std::string_view key,
                                    Problems& r) {
  const KeyRange b = bounds_of(place, key);
  return read_ms(n, key, b.min, b.max, r);
}

// command_refresh_ms: 0 (off), or how often a commander must write a
// node's command for it to stay in force.
std::optional<Duration> read_command_refresh(const toml::node& n, Problems& r) {
  auto v = read_key_ms(n, KeyPlace::kNode, "command_refresh_ms", r);
  if (v && *v > Duration::zero() && *v < milliseconds(kMinCommandRefreshMs)) {
    r.error(n.source(),
            fmt::format("command_refresh_ms = {} is too short: use 0 (off) or {}..{} ms",
                        std::chrono::duration_cast<milliseconds>(*v).count(), kMinCommandRefreshMs,
                        kMaxCommandRefreshMs));
    return std::nullopt;
  }
  return v;
}

}  // namespace dnbridge::daemon::config_detail
