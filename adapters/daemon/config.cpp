#include "adapters/daemon/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <tuple>
#include <utility>

#include "adapters/daemon/host_identity.hpp"
#include "adapters/security/toml_settings.hpp"
#include "adapters/toml/reader.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::daemon {

namespace cdn127 = profiles::cdn127;
using devicenet::MacId;
using toml_config::type_name;

namespace {

using toml_config::IntRange;
using toml_config::Problems;
using toml_config::read_bool;
using toml_config::read_int_as;
using toml_config::read_integer;
using toml_config::read_ms;
using toml_config::read_name;
using toml_config::read_number;
using toml_config::read_string;
using toml_config::TableReader;

std::uint32_t line_of(const toml::source_region& at) {
  return std::max<std::uint32_t>(at.begin.line, 1);
}

const IntRange kMacRange{0, MacId::kMax, {}, "a DeviceNet MAC ID is 0..63"};

std::optional<MacId> read_mac(const toml::node& n, std::string_view key, Problems& r) {
  auto v = read_integer(n, key, kMacRange, r);
  if (!v) return std::nullopt;
  return MacId::from(static_cast<unsigned>(*v));
}

// ---------------------------------------------------------------------------
// Node settings: a node's own keys, else [defaults], else the built-in values.

constexpr std::string_view kProfileCdn127 = "cdn127";
constexpr std::string_view kProfileEds = "eds";

// The keys only a CDN127 node has, and only a profile = "eds" node has.
constexpr std::array<std::string_view, 9> kCdn127OnlyKeys{"io",
                                                          "identity",
                                                          "pump_on_fault",
                                                          "pump_on_idle",
                                                          "n2_ballast_on_fault",
                                                          "n2_ballast_on_idle",
                                                          "analog_output_on_fault",
                                                          "analog_output_on_idle",
                                                          "analog_deadband_volts"};
constexpr std::array<std::string_view, 6> kEdsOnlyKeys{
    "eds", "connection", "parameters", "heartbeat_ms", "inhibit_ms", "acknowledged"};

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

// The device's maximum of one I/O count, as profiles::cdn127::validate knows it.
std::uint8_t device_maximum(std::uint8_t cdn127::IoConfiguration::*count) {
  cdn127::IoConfiguration c{.mode = 0x86,
                            .num_digital_inputs = 0,
                            .num_digital_outputs = 0,
                            .num_analog_inputs = 0,
                            .num_analog_outputs = 0,
                            .no_nc_mask = 0};
  std::uint8_t max = 0;
  for (unsigned v = 1; v <= 0xFF; ++v) {
    c.*count = static_cast<std::uint8_t>(v);
    if (!cdn127::validate(c)) break;
    max = static_cast<std::uint8_t>(v);
  }
  return max;
}

std::optional<cdn127::IoConfiguration> preset_named(std::string_view name) {
  if (name == "cdn127") return cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  if (name == "cdn118") return cdn127::preset(cdn127::ConfigurationPreset::kCdn118);
  return std::nullopt;
}

std::optional<cdn127::IoConfiguration> read_preset(const toml::node& n, std::string_view key,
                                                   Problems& r) {
  auto name = read_string(n, key, r);
  if (!name) return std::nullopt;
  auto io = preset_named(*name);
  if (!io) {
    r.error(n.source(),
            fmt::format("{} = \"{}\" is not a preset: use \"cdn127\" or \"cdn118\"{}", key, *name,
                        key == "io" ? ", or a table of Configuration object values" : ""));
  }
  return io;
}

// `io` is a preset name, or a table of Configuration object values over a
// preset (the CDN127's unless `preset` names another).
std::optional<cdn127::IoConfiguration> read_io(const toml::node& n, Problems& r) {
  if (n.is_string()) return read_preset(n, "io", r);
  const toml::table* t = n.as_table();
  if (!t) {
    r.error(n.source(),
            fmt::format("io must be a preset name (\"cdn127\", \"cdn118\") or a table, not {}",
                        type_name(n.type())));
    return std::nullopt;
  }
  TableReader table(*t, "io", r);
  bool ok = true;
  auto io = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  if (const toml::node* p = table.get("preset")) {
    if (auto base = read_preset(*p, "io.preset", r)) {
      io = *base;
    } else {
      ok = false;
    }
  }
  if (const toml::node* m = table.get("mode")) {
    if (auto v = read_int_as<std::uint8_t>(*m, "io.mode", {0, 0xFF}, r)) {
      io.mode = *v;
      // CDN127 manual, Configuration object, Mode: "Bits 3..5 should be set
      // to 0"; bit 6 is not described. Loaded as given, but said.
      if (*v & 0x78) {
        r.warning(m->source(),
                  fmt::format("io.mode = 0x{:02X} sets bits 3..6, which the CDN127 manual leaves "
                              "reserved",
                              *v));
      }
    } else {
      ok = false;
    }
  }
  if (const toml::node* m = table.get("no_nc_mask")) {
    if (auto v = read_int_as<std::uint8_t>(*m, "io.no_nc_mask", {0, 0xFF}, r)) {
      io.no_nc_mask = *v;
    } else {
      ok = false;
    }
  }
  struct Count {
    std::string_view key;
    std::uint8_t cdn127::IoConfiguration::*field;
  };
  for (const Count& c : {Count{"digital_inputs", &cdn127::IoConfiguration::num_digital_inputs},
                         Count{"digital_outputs", &cdn127::IoConfiguration::num_digital_outputs},
                         Count{"analog_inputs", &cdn127::IoConfiguration::num_analog_inputs},
                         Count{"analog_outputs", &cdn127::IoConfiguration::num_analog_outputs}}) {
    const toml::node* v = table.get(c.key);
    if (!v) continue;
    const std::string key = fmt::format("io.{}", c.key);
    auto count = read_integer(*v, key, {0, 0xFF}, r);
    if (!count) {
      ok = false;
      continue;
    }
    const std::uint8_t max = device_maximum(c.field);
    if (*count > max) {
      r.error(v->source(),
              fmt::format("{} = {} is more than a CDN127 has (at most {})", key, *count, max));
      ok = false;
      continue;
    }
    io.*(c.field) = static_cast<std::uint8_t>(*count);
  }
  if (!ok) return std::nullopt;
  // Whatever the checks above let through, the poll formats must exist.
  if (!cdn127::validate(io) || !cdn127::poll_format(io)) {
    r.error(n.source(), "io is not a configuration a CDN127 accepts");
    return std::nullopt;
  }
  return io;
}

std::optional<devicenet::ExpectedIdentity> read_identity(const toml::node& n, Problems& r) {
  const toml::table* t = n.as_table();
  if (!t) {
    r.error(n.source(),
            fmt::format("identity must be a table {{ vendor_id, product_type, product_code }}, "
                        "not {}",
                        type_name(n.type())));
    return std::nullopt;
  }
  TableReader table(*t, "identity", r);
  devicenet::ExpectedIdentity id;
  bool ok = true;
  auto field = [&](std::string_view key, std::uint16_t& out) {
    const toml::node* v = table.require(key);
    auto value = v ? read_int_as<std::uint16_t>(*v, fmt::format("identity.{}", key), {0, 0xFFFF}, r)
                   : std::nullopt;
    if (value) {
      out = *value;
    } else {
      ok = false;
    }
  };
  field("vendor_id", id.vendor_id);
  field("product_type", id.product_type);
  field("product_code", id.product_code);
  if (!ok) return std::nullopt;
  return id;
}

// DeviceNet expected packet rates are UINT milliseconds (Connection object
// attribute 9); the poll period is bounded by the expected packet rate.
constexpr std::int64_t kMaxPacketRateMs = 0xFFFF;
constexpr std::int64_t kMaxPublishPeriodMs = 3'600'000;
constexpr std::int64_t kMaxPollBatchMs = 1000;
constexpr std::int64_t kMaxResponseTimeoutMs =
    60'000;  // cut to a quarter of each node's poll period
constexpr double kAnalogFullScaleVolts = 10.0;
// A command refresh shorter than a DDS write's round trip under load would
// idle a healthy commander's pumps; longer than ten minutes is no bound.
constexpr std::int64_t kMinCommandRefreshMs = 50;
constexpr std::int64_t kMaxCommandRefreshMs = 600'000;
// A lease shorter than this would have a commander lose its pumps on any
// hiccup of its host; longer than ten minutes is no bound.
constexpr std::int64_t kMinCommanderLeaseMs = 100;
constexpr std::int64_t kMaxCommanderLeaseMs = 600'000;

// The keys of the outputs' safe state, and where each goes.
struct SafeStateKey {
  std::string_view key;
  cdn127::DiscreteAction cdn127::SafeState::*discrete;
  cdn127::AnalogAction cdn127::SafeState::*analog;
};
constexpr std::array<SafeStateKey, 6> kSafeStateKeys{{
    {"pump_on_fault", &cdn127::SafeState::pump_fault, nullptr},
    {"pump_on_idle", &cdn127::SafeState::pump_idle, nullptr},
    {"n2_ballast_on_fault", &cdn127::SafeState::n2_ballast_fault, nullptr},
    {"n2_ballast_on_idle", &cdn127::SafeState::n2_ballast_idle, nullptr},
    {"analog_output_on_fault", nullptr, &cdn127::SafeState::analog_fault},
    {"analog_output_on_idle", nullptr, &cdn127::SafeState::analog_idle},
}};

// "off", "on" or "hold".
std::optional<cdn127::DiscreteAction> read_discrete_action(const toml::node& n,
                                                           std::string_view key, Problems& r) {
  auto v = read_string(n, key, r);
  if (!v) return std::nullopt;
  for (auto a :
       {cdn127::DiscreteAction::kOff, cdn127::DiscreteAction::kOn, cdn127::DiscreteAction::kHold}) {
    if (*v == cdn127::to_string(a)) return a;
  }
  r.error(
      n.source(),
      fmt::format("{} = \"{}\" is not an output action: use \"off\", \"on\" or \"hold\"", key, *v));
  return std::nullopt;
}

// A voltage, 0..10, or "hold".
std::optional<cdn127::AnalogAction> read_analog_action(const toml::node& n, std::string_view key,
                                                       Problems& r) {
  if (n.is_string()) {
    auto v = read_string(n, key, r);
    if (v && *v == "hold") return cdn127::AnalogAction{cdn127::AnalogAction::Kind::kHold, 0};
    if (v) {
      r.error(n.source(), fmt::format("{} = \"{}\" is not an analog output action: use a voltage "
                                      "(0..10, e.g. 0.0) or \"hold\"",
                                      key, *v));
    }
    return std::nullopt;
  }
  auto volts = read_number(n, key, r);
  if (!volts) return std::nullopt;
  auto raw = cdn127::volts_to_raw(*volts);
  if (!raw) {
    r.error(n.source(), fmt::format("{} = {} V is out of range (0..10 V)", key, *volts));
    return std::nullopt;
  }
  return cdn127::AnalogAction{cdn127::AnalogAction::Kind::kValue, *raw};
}

void read_safe_state(const Layers& layers, NodeSettings& s, Problems& r) {
  if (Found f = layers.find("safe_state"); f.value) {
    if (auto v = read_string(*f.value, "safe_state", r)) {
      if (*v == "configured") {
        s.pump.safe_state.source = cdn127::SafeStateSource::kConfiguration;
      } else if (*v == "device") {
        s.pump.safe_state.source = cdn127::SafeStateSource::kDevice;
      } else {
        r.error(f.value->source(),
                fmt::format("safe_state = \"{}\" is not a choice: use \"configured\" (the "
                            "default: the keys pump_on_fault ... are downloaded) or \"device\"",
                            *v));
      }
    }
  }
  const bool keep_device = s.pump.safe_state.source == cdn127::SafeStateSource::kDevice;
  for (const auto& k : kSafeStateKeys) {
    const Found f = layers.find(k.key);
    if (!f.value) continue;
    // A node that keeps the device's values and gives values of its own
    // says two things; [defaults] may give values other nodes use.
    if (keep_device && f.level == Level::kNode) {
      r.error(f.value->source(),
              fmt::format("{} has no effect with safe_state = \"device\": the device's own "
                          "fault and idle actions are kept",
                          k.key));
      continue;
    }
    if (k.discrete) {
      if (auto v = read_discrete_action(*f.value, k.key, r))
        s.pump.safe_state.values.*k.discrete = *v;
    } else if (auto v = read_analog_action(*f.value, k.key, r)) {
      s.pump.safe_state.values.*k.analog = *v;
    }
  }
  // Opt-ins that give up a guarantee: said in the log at every start.
  if (layers.per_node() && keep_device) {
    const Found f = layers.find("safe_state");
    r.warning(f.value->source(),
              fmt::format("node {} keeps the device's own fault and idle actions "
                          "(safe_state = \"device\"): read and shown, never written",
                          s.pump.node.mac.value()));
  }
}

// resume: what a node's outputs do when it is back after a loss.
void read_resume(const Layers& layers, NodeSettings& s, Problems& r) {
  if (Found f = layers.find("resume"); f.value) {
    if (auto v = read_string(*f.value, "resume", r)) {
      if (*v == "new-command") {
        s.pump.resume = rack::ResumePolicy::kFreshCommand;
      } else if (*v == "last-command") {
        s.pump.resume = rack::ResumePolicy::kLastCommand;
      } else {
        r.error(f.value->source(),
                fmt::format("resume = \"{}\" is not a policy: use \"new-command\" (the "
                            "default) or \"last-command\"",
                            *v));
      }
    }
  }
  if (layers.per_node() && s.pump.resume == rack::ResumePolicy::kLastCommand) {
    const Found f = layers.find("resume");
    r.warning(
        f.value->source(),
        fmt::format("node {} drives its last outputs again after a loss without a new "
                    "command (resume = \"last-command\"): {} may start on its own "
                    "after a power cycle",
                    s.pump.node.mac.value(), s.is_eds() ? "what its outputs drive" : "a pump"));
  }
}

// command_refresh_ms: 0 (off), or how often a commander must write a
// node's command for it to stay in force.
std::optional<Duration> read_command_refresh(const toml::node& n, Problems& r) {
  auto v = read_ms(n, "command_refresh_ms", 0, kMaxCommandRefreshMs, r);
  if (v && *v > Duration::zero() && *v < milliseconds(kMinCommandRefreshMs)) {
    r.error(n.source(),
            fmt::format("command_refresh_ms = {} is too short: use 0 (off) or {}..{} ms",
                        std::chrono::duration_cast<milliseconds>(*v).count(), kMinCommandRefreshMs,
                        kMaxCommandRefreshMs));
    return std::nullopt;
  }
  return v;
}

// Reads every setting a node and [defaults] share into `s`, which holds the
// built-in values to start with.
void read_node_settings(const Layers& layers, NodeSettings& s, Problems& r) {
  if (Found f = layers.find("profile"); f.value) {
    if (auto v = read_string(*f.value, "profile", r)) {
      if (*v == kProfileCdn127 || *v == kProfileEds) {
        s.profile = *v;
      } else {
        r.error(f.value->source(),
                fmt::format("profile \"{}\" is not a profile: use \"cdn127\" (the default) or "
                            "\"eds\" (a device described by its EDS file)",
                            *v));
      }
    }
  }
  // A CDN127's own settings; a node of another profile refuses them
  // (read_eds_node), [defaults] may hold them for the CDN127s.
  const bool cdn127 = s.profile == kProfileCdn127;
  if (Found f = layers.find("io"); f.value && cdn127) {
    if (auto v = read_io(*f.value, r)) s.pump.io = *v;
  }
  if (Found f = layers.find("identity"); f.value && cdn127) {
    if (auto v = read_identity(*f.value, r)) s.pump.identity = *v;
  }

  const Found poll = layers.find("poll_period_ms");
  const Found epr = layers.find("expected_packet_rate_ms");
  bool poll_ok = true, epr_ok = true;
  if (poll.value) {
    auto v = read_ms(*poll.value, "poll_period_ms", 1, kMaxPacketRateMs, r);
    poll_ok = v.has_value();
    if (v) s.pump.node.poll_period = *v;
  }
  if (epr.value) {
    auto v = read_ms(*epr.value, "expected_packet_rate_ms", 1, kMaxPacketRateMs, r);
    epr_ok = v.has_value();
    if (v) s.pump.node.expected_packet_rate = *v;
  }
  // Compared per node only: [defaults] alone may rely on what nodes add.
  const bool per_node = layers.per_node();
  if (per_node && poll_ok && epr_ok && s.pump.node.expected_packet_rate < s.pump.node.poll_period) {
    // Reported where the more specific of the two is written.
    const bool at_epr = epr.level >= poll.level;
    const Found& here = at_epr ? epr : poll;
    r.error(here.value->source(),
            fmt::format(
                "expected_packet_rate_ms = {}{} is shorter than poll_period_ms = {}{}: the "
                "node expects a poll at least once per expected packet rate",
                std::chrono::duration_cast<milliseconds>(s.pump.node.expected_packet_rate).count(),
                at_epr ? std::string() : origin(epr),
                std::chrono::duration_cast<milliseconds>(s.pump.node.poll_period).count(),
                at_epr ? origin(poll) : std::string()));
  }
  if (Found f = layers.find("explicit_packet_rate_ms"); f.value) {
    if (auto v = read_ms(*f.value, "explicit_packet_rate_ms", 1, kMaxPacketRateMs, r)) {
      s.pump.node.explicit_packet_rate = *v;
    }
  }
  if (Found f = layers.find("immediate_poll"); f.value) {
    if (auto v = read_bool(*f.value, "immediate_poll", r))
      s.pump.node.immediate_poll_on_change = *v;
  }
  if (const Found gap = layers.find("immediate_poll_min_gap_ms"); gap.value) {
    if (auto v = read_ms(*gap.value, "immediate_poll_min_gap_ms", 0, kMaxPacketRateMs, r)) {
      s.pump.node.immediate_poll_min_gap = *v;
      // Longer than the poll period it would only hold back changes the
      // node's next slot carries anyway: a mistake, not a setting.
      if (per_node && poll_ok && *v > s.pump.node.poll_period) {
        const bool at_gap = gap.level >= poll.level;
        const Found& here = at_gap ? gap : poll;
        r.error(
            here.value->source(),
            fmt::format("immediate_poll_min_gap_ms = {}{} is longer than poll_period_ms = "
                        "{}{}: polls for changed outputs may be held back at most a poll "
                        "period",
                        std::chrono::duration_cast<milliseconds>(*v).count(),
                        at_gap ? std::string() : origin(gap),
                        std::chrono::duration_cast<milliseconds>(s.pump.node.poll_period).count(),
                        at_gap ? origin(poll) : std::string()));
      }
    }
  } else if (per_node && poll_ok) {
    // The built-in gap, for a node polled faster than it: the poll period.
    s.pump.node.immediate_poll_min_gap =
        std::min(s.pump.node.immediate_poll_min_gap, s.pump.node.poll_period);
  }
  if (Found f = layers.find("publish_max_period_ms"); f.value) {
    if (auto v = read_ms(*f.value, "publish_max_period_ms", 1, kMaxPublishPeriodMs, r)) {
      s.publish.max_period = *v;
      if (per_node && poll_ok && *v < s.pump.node.poll_period) {
        r.warning(
            f.value->source(),
            fmt::format("publish_max_period_ms = {} is shorter than poll_period_ms = {}{}: "
                        "samples in between repeat the last poll",
                        std::chrono::duration_cast<milliseconds>(*v).count(),
                        std::chrono::duration_cast<milliseconds>(s.pump.node.poll_period).count(),
                        f.level == poll.level ? std::string() : origin(poll)));
      }
    }
  }
  if (Found f = layers.find("analog_deadband_volts"); f.value && cdn127) {
    if (auto v = read_number(*f.value, "analog_deadband_volts", r)) {
      if (*v < 0 || *v > kAnalogFullScaleVolts) {
        r.error(f.value->source(),
                fmt::format("analog_deadband_volts = {} is out of range (0..10 V)", *v));
      } else {
        s.publish.analog_deadband_volts = *v;
      }
    }
  }
  if (Found f = layers.find("explicit_response_timeout_ms"); f.value) {
    if (auto v = read_ms(*f.value, "explicit_response_timeout_ms", 1, kMaxResponseTimeoutMs, r)) {
      s.pump.node.explicit_response_timeout = *v;
    }
  }
  if (Found f = layers.find("poll_response_timeout_ms"); f.value) {
    if (auto v = read_ms(*f.value, "poll_response_timeout_ms", 1, kMaxResponseTimeoutMs, r)) {
      s.pump.node.poll_response_timeout = *v;
    }
  }
  if (Found f = layers.find("no_commander"); f.value) {
    if (auto v = read_string(*f.value, "no_commander", r)) {
      if (*v == "idle") {
        s.pump.no_commander = NoCommanderPolicy::kIdle;
      } else if (*v == "hold") {
        s.pump.no_commander = NoCommanderPolicy::kHoldLastOutputs;
      } else {
        r.error(f.value->source(),
                fmt::format("no_commander = \"{}\" is not a policy: use \"idle\" or \"hold\"", *v));
      }
    }
  }
  if (Found f = layers.find("command_refresh_ms"); f.value) {
    if (auto v = read_command_refresh(*f.value, r)) s.pump.command_refresh = *v;
  }
  if (cdn127) read_safe_state(layers, s, r);
  read_resume(layers, s, r);
}

// ---------------------------------------------------------------------------
// Nodes described by their EDS files (profile = "eds").

// What reading one configuration keeps besides its problems: where relative
// EDS paths start, and each EDS file read, once.
struct EdsRead {
  std::shared_ptr<const eds::EdsFile> file;  // null: not usable
  std::uint64_t digest = 0;
  std::uint32_t first_line = 0;  // of the `eds` key that read it
};
struct ReadContext {
  std::filesystem::path base_dir;
  std::map<std::string, EdsRead> eds_files;  // by resolved path
};

// 64-bit FNV-1a: a changed file is told from the one in force.
std::uint64_t digest_of(std::string_view text) {
  std::uint64_t h = 14695981039346656037ULL;
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

// The EDS file at `path`, read and checked at its first use, its problems
// reported there (each "FILE:LINE: ..." of the EDS, at the `eds` key).
const EdsRead& read_eds_file(const std::string& path, const toml::node& key, ReadContext& ctx,
                             Problems& r) {
  auto [it, first] = ctx.eds_files.try_emplace(path);
  EdsRead& e = it->second;
  if (!first) {
    if (!e.file) {
      r.error(key.source(), fmt::format("eds = \"{}\" is not usable (its problems are listed at "
                                        "line {})",
                                        path, e.first_line));
    }
    return e;
  }
  e.first_line = line_of(key.source());
  auto text = toml_config::read_file(path, "an EDS file");
  if (!text.text) {
    r.error(key.source(), fmt::format("eds: {}", text.error));
    return e;
  }
  const eds::Parsed parsed = eds::parse(*text.text);
  for (const auto& problem : parsed.problems) {
    const std::string line = fmt::format("eds: {}", eds::format_problem(path, problem));
    if (problem.severity == eds::Problem::Severity::kError) {
      r.error(key.source(), line);
    } else {
      r.warning(key.source(), line);
    }
  }
  if (parsed.not_shown > 0) {
    r.error(key.source(), fmt::format("eds: {}: {} more problems not shown ({} errors in all)",
                                      path, parsed.not_shown, parsed.errors));
  }
  if (parsed.file) {
    e.file = std::make_shared<const eds::EdsFile>(*parsed.file);
    e.digest = digest_of(*text.text);
  }
  return e;
}

// connection = "poll" | "bit-strobe" | "change-of-state" | "cyclic".
std::optional<eds::ConnectionKind> read_connection(const toml::node& n, Problems& r) {
  auto v = read_string(n, "connection", r);
  if (!v) return std::nullopt;
  static constexpr std::pair<std::string_view, eds::ConnectionKind> kKinds[] = {
      {"poll", eds::ConnectionKind::kPoll},
      {"bit-strobe", eds::ConnectionKind::kStrobe},
      {"change-of-state", eds::ConnectionKind::kChangeOfState},
      {"cyclic", eds::ConnectionKind::kCyclic}};
  for (const auto& [name, kind] : kKinds) {
    if (*v == name) return kind;
  }
  r.error(n.source(), fmt::format("connection = \"{}\" is not a connection: use \"poll\", "
                                  "\"bit-strobe\", \"change-of-state\" or \"cyclic\"",
                                  *v));
  return std::nullopt;
}

// KEY = [{ name = "...", value = N }, ...]: EDS parameters by name, in order.
std::optional<std::vector<eds::ParameterValue>> read_parameter_values(const toml::node& n,
                                                                      std::string_view key,
                                                                      Problems& r) {
  const toml::array* list = n.as_array();
  if (!list || (!list->empty() && !list->is_array_of_tables())) {
    r.error(n.source(), fmt::format("{} must be an array of {{ name = \"...\", value = ... }}, "
                                    "not {}",
                                    key, type_name(n.type())));
    return std::nullopt;
  }
  std::vector<eds::ParameterValue> out;
  bool ok = true;
  for (const toml::node& element : *list) {
    TableReader t(*element.as_table(), std::string(key), r);
    const toml::node* name = t.require("name");
    const toml::node* value = t.require("value");
    auto name_v = name ? read_string(*name, fmt::format("{}.name", key), r) : std::nullopt;
    auto value_v = value ? read_number(*value, fmt::format("{}.value", key), r) : std::nullopt;
    if (name_v && value_v) {
      out.push_back({*name_v, *value_v});
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

// A profile = "eds" node's own keys: eds (the file, relative to the
// configuration's directory), connection, parameters, safe_state; checked
// against the EDS as the master will take them.
void read_eds_node(TableReader& nt, ReadContext& ctx, NodeSettings& s, Problems& r) {
  for (std::string_view key : kCdn127OnlyKeys) {
    if (const toml::node* n = nt.get(key)) {
      r.error(n->source(),
              fmt::format("{} is a CDN127 setting: this node has profile = \"eds\"", key));
    }
  }
  const toml::node* connection = nt.get("connection");
  bool connection_known = true;
  if (connection) {
    auto v = read_connection(*connection, r);
    if (v) s.eds_node.connection = *v;
    connection_known = v.has_value();
  }
  // The change-of-state or cyclic connection's own settings.
  const bool cos = s.eds_node.connection == eds::ConnectionKind::kChangeOfState ||
                   s.eds_node.connection == eds::ConnectionKind::kCyclic;
  for (std::string_view k : {"heartbeat_ms", "inhibit_ms", "acknowledged"}) {
    const toml::node* n = nt.get(k);
    if (n == nullptr || !connection_known) continue;
    if (!cos) {
      r.error(n->source(), fmt::format("{} is for connection = \"change-of-state\" or "
                                       "\"cyclic\" (this node's is \"{}\")",
                                       k, to_string(s.eds_node.connection)));
    } else if (k == "heartbeat_ms") {
      if (auto v = read_ms(*n, k, 1, kMaxPacketRateMs, r)) s.eds_node.heartbeat = *v;
    } else if (k == "inhibit_ms") {
      if (s.eds_node.connection == eds::ConnectionKind::kCyclic) {
        r.error(n->source(),
                "inhibit_ms is for connection = \"change-of-state\": a cyclic "
                "connection produces every heartbeat_ms, changes or not");
      } else if (auto v = read_ms(*n, k, 0, kMaxPacketRateMs, r)) {
        s.eds_node.inhibit = *v;
        if (*v >= s.eds_node.heartbeat) {
          r.error(
              n->source(),
              fmt::format("inhibit_ms = {} is not shorter than heartbeat_ms ({}): "
                          "changes could never be sent sooner than heartbeats",
                          std::chrono::duration_cast<milliseconds>(*v).count(),
                          std::chrono::duration_cast<milliseconds>(s.eds_node.heartbeat).count()));
        }
      }
    } else if (auto v = read_bool(*n, k, r)) {
      s.eds_node.acknowledged = *v;
    }
  }
  const toml::node* parameters = nt.get("parameters");
  if (parameters) {
    if (auto v = read_parameter_values(*parameters, "parameters", r)) s.eds_node.parameters = *v;
  }
  // The parameters that set the outputs' fault and idle actions, or
  // "device": the device's own, fixed by its maker.
  const toml::node* safe = nt.get("safe_state");
  if (safe && safe->is_string()) {
    if (auto v = read_string(*safe, "safe_state", r); v && *v == "device") {
      s.eds_node.safe_state_of_device = true;
    } else if (v) {
      r.error(safe->source(),
              fmt::format("safe_state = \"{}\" is not a choice for profile = \"eds\": give the "
                          "parameters that set the outputs' fault and idle actions "
                          "([{{ name = \"...\", value = ... }}]), or \"device\" where the "
                          "device's maker fixes them",
                          *v));
    }
  } else if (safe) {
    if (auto v = read_parameter_values(*safe, "safe_state", r)) s.eds_node.safe_state = *v;
  }
  const toml::node* key = nt.require("eds");
  if (!key) return;
  auto given = read_string(*key, "eds", r);
  if (!given) return;
  std::filesystem::path path(*given);
  if (path.is_relative() && !ctx.base_dir.empty()) path = ctx.base_dir / path;
  s.eds_path = path.lexically_normal().string();
  const EdsRead& e = read_eds_file(s.eds_path, *key, ctx, r);
  if (!e.file) return;
  s.eds = e.file;
  s.eds_digest = e.digest;
  // Outputs whose safe state the node leaves as the device has it.
  const auto& io = eds::node_io(*e.file, s.eds_node.connection);
  if (io && io->consumed.size > 0 && s.eds_node.safe_state_of_device) {
    const auto names = [](const std::vector<const eds::Param*>& params) {
      std::string text;
      for (const eds::Param* p : params) {
        text += fmt::format("{}Param{} \"{}\"", text.empty() ? "" : ", ", p->number, p->name);
      }
      return text;
    };
    const eds::DeviceSafeState d = eds::device_safe_state(*e.file, s.eds_node);
    r.warning(safe->source(),
              fmt::format("node {}: its outputs' fault and idle behaviour is the device's own "
                          "(safe_state = \"device\"): {}, never written",
                          s.pump.node.mac.value(),
                          d.read.empty() ? std::string("its EDS names no parameter to read")
                                         : "read at start-up: " + names(d.read)));
    if (!d.unread.empty()) {
      r.warning(safe->source(),
                fmt::format("node {}: {} not read (no link path to an attribute, or not of 1, 2 "
                            "or 4 bytes): not shown",
                            s.pump.node.mac.value(), names(d.unread)));
    }
    if (!d.written.empty()) {
      r.warning(safe->source(),
                fmt::format("node {}: {} set in parameters although safe_state = \"device\": "
                            "written all the same",
                            s.pump.node.mac.value(), names(d.written)));
    }
  } else if (io && io->consumed.size > 0) {
    for (const eds::Param* p : eds::safe_state_left_to_device(*e.file, s.eds_node)) {
      r.warning(key->source(),
                fmt::format("node {}: Param{} \"{}\" is set neither in safe_state nor in "
                            "parameters: the device keeps its own value",
                            s.pump.node.mac.value(), p->number, p->name));
    }
  }
  std::string why;
  if (!eds::make_node_profile(e.file, s.eds_node, &why)) {
    // At the key the problem is about.
    const toml::node* at = key;
    if (why.starts_with("parameters") && parameters) at = parameters;
    if (why.starts_with("safe_state") && safe) at = safe;
    if ((why.starts_with("connection") || why.starts_with("the EDS offers")) && connection) {
      at = connection;
    }
    r.error(at->source(),
            fmt::format("node {} ({}): {}", s.pump.node.mac.value(), s.eds_path, why));
  }
}

// ---------------------------------------------------------------------------
// Ports.

// A SocketCAN interface name: at most IFNAMSIZ - 1 = 15 characters, no slash
// or white space (what the kernel accepts as a network device name).
bool valid_interface_name(std::string_view name) {
  if (name.empty() || name.size() > 15 || name == "." || name == "..") return false;
  return std::none_of(name.begin(), name.end(), [](char c) {
    return c == '/' || c == ':' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\0';
  });
}

struct NodeSeen {
  std::string name;
  std::uint32_t line;
};

// simulated_unconfigured = [MAC, ...]: a simulated port's devices at MACs
// its nodes do not have.
void read_simulated_unconfigured(const toml::node& n, PortConfig& port, Problems& r) {
  const toml::array* list = n.as_array();
  if (!list) {
    r.error(n.source(), fmt::format("simulated_unconfigured must be an array of MAC IDs, not {}",
                                    type_name(n.type())));
    return;
  }
  if (port.interface != kSimulatedInterface) {
    r.error(n.source(), "simulated_unconfigured is for a port whose interface is \"simulated\"");
    return;
  }
  for (const toml::node& element : *list) {
    auto mac = read_mac(element, "simulated_unconfigured", r);
    if (!mac) continue;
    const bool configured = std::any_of(port.nodes.begin(), port.nodes.end(),
                                        [&](const auto& s) { return s.pump.node.mac == *mac; });
    if (configured || *mac == port.master.master_mac) {
      r.error(element.source(), fmt::format("simulated_unconfigured: MAC {} is {}", mac->value(),
                                            configured ? "a configured node's" : "the master's"));
    } else if (std::find(port.simulated_unconfigured.begin(), port.simulated_unconfigured.end(),
                         *mac) != port.simulated_unconfigured.end()) {
      r.error(element.source(),
              fmt::format("simulated_unconfigured: MAC {} is given twice", mac->value()));
    } else {
      port.simulated_unconfigured.push_back(*mac);
    }
  }
}

void read_port_nodes(TableReader& t, const toml::table& table, PortConfig& port,
                     TableReader* defaults, ReadContext& ctx, Problems& r);

PortConfig read_port(const toml::table& table, const DaemonConfig& rack, TableReader* defaults,
                     ReadContext& ctx, Problems& r) {
  TableReader t(table, "[[port]]", r);
  PortConfig port;
  port.master.master_mac = rack.master_mac;
  if (const toml::node* n = t.require("name")) {
    if (auto v = read_name(*n, "name", r)) port.name = *v;
  }
  if (const toml::node* n = t.require("interface")) {
    if (auto v = read_string(*n, "interface", r)) {
      if (*v == kSimulatedInterface || valid_interface_name(*v)) {
        port.interface = *v;
      } else {
        r.error(n->source(),
                fmt::format("interface = \"{}\" is not a CAN interface name: use \"simulated\" or "
                            "a SocketCAN interface such as \"can0\" (at most 15 characters)",
                            *v));
      }
    }
  }
  if (const toml::node* n = t.require("bitrate")) {
    if (auto v = read_integer(
            *n, "bitrate",
            {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()},
            r)) {
      if (*v == 125000 || *v == 250000 || *v == 500000) {
        port.bitrate = static_cast<std::uint32_t>(*v);
      } else {
        r.error(n->source(),
                fmt::format(
                    "bitrate = {} is not a DeviceNet bit rate: use 125000, 250000 or 500000", *v));
      }
    }
  }
  if (const toml::node* n = t.get("bus_off_recovery")) {
    if (auto v = read_string(*n, "bus_off_recovery", r)) {
      if (*v == "interface") {
        port.bus_off_recovery = BusOffRecovery::kInterface;
      } else if (*v == "restart") {
        port.bus_off_recovery = BusOffRecovery::kRestart;
      } else if (*v == "report") {
        port.bus_off_recovery = BusOffRecovery::kReport;
      } else {
        r.error(n->source(),
                fmt::format("bus_off_recovery = \"{}\" is not a policy: use \"interface\", "
                            "\"restart\" or \"report\"",
                            *v));
      }
    }
  }
  const toml::node* master_mac_node = t.get("master_mac");
  if (master_mac_node) {
    if (auto v = read_mac(*master_mac_node, "master_mac", r)) port.master.master_mac = *v;
  }
  if (const toml::node* n = t.get("master_vendor_id")) {
    if (auto v = read_int_as<std::uint16_t>(*n, "master_vendor_id", {0, 0xFFFF}, r)) {
      port.master.vendor_id = *v;
    }
  }
  if (const toml::node* n = t.get("master_serial_number")) {
    if (auto v = read_int_as<std::uint32_t>(*n, "master_serial_number", {0, 0xFFFF'FFFF}, r)) {
      port.master_serial_number = *v;
    }
  }

  auto timing = [&](std::string_view key, Duration& out) {
    if (const toml::node* n = t.get(key)) {
      if (auto v = read_ms(*n, key, 1, kMaxPublishPeriodMs, r)) out = *v;
    }
  };
  devicenet::ScannerConfig& tm = port.master;
  timing("allocate_retry_min_ms", tm.allocate_retry_min);
  timing("allocate_retry_max_ms", tm.allocate_retry_max);
  timing("fault_recheck_ms", tm.fault_recheck);
  timing("poll_response_timeout_ms", tm.poll_response_timeout);
  timing("explicit_response_timeout_ms", tm.explicit_messaging.response_timeout);
  timing("scan_response_timeout_ms", tm.scan_response_timeout);
  if (const toml::node* n = t.get("poll_batch_ms")) {
    if (auto v = read_ms(*n, "poll_batch_ms", 0, kMaxPollBatchMs, r)) tm.poll_batch_window = *v;
  }
  if (const toml::node* n = t.get("max_consecutive_errors")) {
    if (auto v = read_int_as<unsigned>(*n, "max_consecutive_errors", {1, 1000}, r)) {
      tm.max_consecutive_errors = *v;
    }
  }
  if (tm.allocate_retry_max < tm.allocate_retry_min) {
    const toml::node* n = t.get("allocate_retry_max_ms");
    if (!n) n = t.get("allocate_retry_min_ms");
    r.error(n ? n->source() : table.source(),
            "allocate_retry_max_ms is shorter than allocate_retry_min_ms");
  }

  if (const toml::node* n = t.get("command_refresh_ms")) {
    port.command_refresh = read_command_refresh(*n, r);
  }

  read_port_nodes(t, table, port, defaults, ctx, r);
  if (const toml::node* n = t.get("simulated_unconfigured")) {
    read_simulated_unconfigured(*n, port, r);
  }
  return port;
}

// The port's [[port.node]] tables.
void read_port_nodes(TableReader& t, const toml::table& table, PortConfig& port,
                     TableReader* defaults, ReadContext& ctx, Problems& r) {
  const toml::node* master_mac_node = t.get("master_mac");
  const toml::node* nodes = t.get("node");
  const toml::array* list = nodes ? nodes->as_array() : nullptr;
  if (nodes && (!list || !list->is_array_of_tables())) {
    r.error(nodes->source(), fmt::format("node must be an array of tables ([[port.node]]), not {}",
                                         type_name(nodes->type())));
    return;
  }
  if (!list || list->empty()) {
    r.warning(table.source(), fmt::format("port \"{}\" has no [[port.node]]: its master scans "
                                          "nothing",
                                          port.name));
    return;
  }

  std::map<std::uint8_t, NodeSeen> macs;
  std::map<std::string, std::uint32_t> names;
  for (const toml::node& element : *list) {
    TableReader nt(*element.as_table(), "[[port.node]]", r);
    NodeSettings s;
    bool ok = true;
    const toml::node* mac_node = nt.require("mac");
    const toml::node* name_node = nt.require("name");
    std::optional<MacId> mac = mac_node ? read_mac(*mac_node, "mac", r) : std::nullopt;
    std::optional<std::string> name = name_node ? read_name(*name_node, "name", r) : std::nullopt;
    if (mac) {
      s.pump.node.mac = *mac;
      if (*mac == port.master.master_mac) {
        r.error(mac_node->source(),
                fmt::format(
                    "mac = {} is the master's own MAC on port \"{}\"{}", mac->value(), port.name,
                    master_mac_node
                        ? fmt::format(" (master_mac, line {})", line_of(master_mac_node->source()))
                        : std::string(" (the rack's master_mac)")));
        ok = false;
      }
      const std::uint32_t line = line_of(mac_node->source());
      auto [it, added] = macs.try_emplace(mac->value(), NodeSeen{name.value_or(""), line});
      if (!added) {
        r.error(mac_node->source(),
                fmt::format("mac = {} is already used on port \"{}\" by node \"{}\" (line {})",
                            mac->value(), port.name, it->second.name, it->second.line));
        ok = false;
      }
    } else {
      ok = false;
    }
    if (const toml::node* serial = nt.get("serial")) {
      if (auto v = read_int_as<std::uint32_t>(*serial, "serial", {0, 0xFFFF'FFFF}, r)) {
        s.pump.node.serial_number = *v;
      } else {
        ok = false;
      }
    }
    if (name) {
      s.pump.node.name = *name;
      const std::uint32_t line = line_of(name_node->source());
      auto [it, added] = names.try_emplace(*name, line);
      if (!added) {
        r.error(name_node->source(),
                fmt::format("name \"{}\" is already used on port \"{}\" (line {})", *name,
                            port.name, it->second));
        ok = false;
      }
    } else {
      ok = false;
    }
    read_node_settings(Layers{&nt, defaults}, s, r);
    // The port's command refresh before [defaults]', after the node's own.
    if (port.command_refresh && !nt.get("command_refresh_ms")) {
      s.pump.command_refresh = *port.command_refresh;
    }
    if (s.pump.command_refresh > Duration::zero() &&
        s.pump.no_commander == NoCommanderPolicy::kHoldLastOutputs && name_node) {
      r.warning(name_node->source(),
                fmt::format("node \"{}\" has a command refresh and no_commander = \"hold\": "
                            "the outputs of a commander that falls silent stay as it left them",
                            s.pump.node.name));
    }
    if (s.is_eds()) {
      read_eds_node(nt, ctx, s, r);
    } else {
      for (std::string_view key : kEdsOnlyKeys) {
        if (const toml::node* n = nt.get(key)) {
          r.error(n->source(), fmt::format("{} is for profile = \"eds\" nodes", key));
        }
      }
    }
    if (ok) port.nodes.push_back(std::move(s));
  }
}

// [explicit_policy]: one true/false key per class of guarded request, named
// by the policy itself.
rack::ExplicitPolicy read_explicit_policy(const toml::node& n, Problems& r) {
  rack::ExplicitPolicy policy;
  const toml::table* t = n.as_table();
  if (!t) {
    r.error(n.source(), fmt::format("explicit_policy must be a table ([explicit_policy]), not {}",
                                    type_name(n.type())));
    return policy;
  }
  std::array<std::string_view, rack::kGuardedRequestKinds> keys{};
  for (std::size_t i = 0; i < keys.size(); ++i) {
    keys[i] = rack::policy_key(static_cast<rack::GuardedRequest>(i));
  }
  TableReader table(*t, "[explicit_policy]", r);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (const toml::node* v = table.get(keys[i])) {
      if (auto allowed = read_bool(*v, keys[i], r)) {
        policy.allow(static_cast<rack::GuardedRequest>(i), *allowed);
      }
    }
  }
  return policy;
}

// [metrics]: listen = "HOST:PORT". IPv4 only: Debian's civetweb, which the
// metrics server is built on, has no IPv6.
std::optional<std::string> read_metrics(const toml::node& n, Problems& r) {
  const toml::table* t = toml_config::as_table(n, "metrics", "[metrics]", r);
  if (!t) return std::nullopt;
  TableReader table(*t, "[metrics]", r);
  const toml::node* listen = table.require("listen");
  if (!listen) return std::nullopt;
  auto v = read_string(*listen, "listen", r);
  if (!v) return std::nullopt;
  // HOST:PORT with a port 1..65535; the host a name or an IPv4 address.
  const auto colon = v->rfind(':');
  const std::string host = colon == std::string::npos ? std::string{} : v->substr(0, colon);
  const std::string port = colon == std::string::npos ? std::string{} : v->substr(colon + 1);
  unsigned long number = 0;
  const bool port_ok = !port.empty() && port.size() <= 5 &&
                       port.find_first_not_of("0123456789") == std::string::npos &&
                       (number = std::stoul(port)) >= 1 && number <= 65535;
  if (!host.empty() && (host.front() == '[' || host.find(':') != std::string::npos)) {
    r.error(listen->source(),
            fmt::format("listen = \"{}\": the metrics server has no IPv6 (Debian's civetweb is "
                        "built without it); use an IPv4 address or a host name, e.g. "
                        "\"127.0.0.1:9731\"",
                        *v));
    return std::nullopt;
  }
  if (!port_ok || host.empty()) {
    r.error(listen->source(),
            fmt::format("listen = \"{}\" is not HOST:PORT (e.g. \"127.0.0.1:9731\"; the port "
                        "1..65535)",
                        *v));
    return std::nullopt;
  }
  return *v;
}

std::optional<LogLevel> log_level_named(std::string_view name) {
  for (LogLevel l :
       {LogLevel::kTrace, LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarn, LogLevel::kError}) {
    if (to_string(l) == name) return l;
  }
  return std::nullopt;
}

// RTPS maps domain IDs to UDP ports; with the standard port parameters the
// highest that fits is 232.
constexpr std::int64_t kMaxDomainId = 232;

DaemonConfig read_rack(const toml::table& table, std::string_view source, ReadContext& ctx,
                       Problems& r) {
  TableReader root(table, "the top level", r);
  DaemonConfig config;
  config.source = std::string(source);
  if (const toml::node* n = root.require("rack")) {
    if (auto v = read_name(*n, "rack", r)) {
      // The rack's DDS partition is named after it (dds::rack_partition),
      // where these match as patterns.
      const bool control = std::any_of(v->begin(), v->end(), [](char c) {
        return static_cast<unsigned char>(c) < 0x20 || c == '\x7F';
      });
      if (control || v->find_first_of("*?") != std::string::npos) {
        r.error(
            n->source(),
            fmt::format("rack = \"{}\": a rack name holds no '*', '?' or control character (its "
                        "DDS partition, dnbridge/RACK, would match other racks' as a pattern, "
                        "or be cut short)",
                        control ? std::string("...") : *v));
      } else {
        config.rack = *v;
      }
    }
  }
  if (const toml::node* n = root.get("domain")) {
    if (auto v = read_int_as<std::uint32_t>(
            *n, "domain", {0, kMaxDomainId, {}, "a DDS domain ID is 0..232"}, r)) {
      config.domain_id = *v;
    }
  }
  if (const toml::node* n = root.get("master_mac")) {
    if (auto v = read_mac(*n, "master_mac", r)) config.master_mac = *v;
  }
  if (const toml::node* n = root.get("max_commander_lease_ms")) {
    if (auto v =
            read_ms(*n, "max_commander_lease_ms", kMinCommanderLeaseMs, kMaxCommanderLeaseMs, r)) {
      config.max_commander_lease = *v;
    }
  }
  if (const toml::node* n = root.get("log_level")) {
    if (auto v = read_string(*n, "log_level", r)) {
      if (auto l = log_level_named(*v)) {
        config.log_level = *l;
      } else {
        r.error(
            n->source(),
            fmt::format("log_level = \"{}\" is not a level: use \"trace\", \"debug\", \"info\", "
                        "\"warn\" or \"error\"",
                        *v));
      }
    }
  }

  if (const toml::node* n = root.get("explicit_policy")) {
    config.explicit_policy = read_explicit_policy(*n, r);
  }

  if (const toml::node* n = root.get("security")) {
    config.security = security::read_table(*n, r);
  }

  if (const toml::node* n = root.get("metrics")) {
    config.metrics_listen = read_metrics(*n, r);
  }

  std::optional<TableReader> defaults;
  if (const toml::node* n = root.get("defaults")) {
    if (const toml::table* t = toml_config::as_table(*n, "defaults", "[defaults]", r)) {
      defaults.emplace(*t, "[defaults]", r);
      // Read once on their own, so that their problems are reported even
      // when no node inherits them.
      NodeSettings ignored;
      read_node_settings(Layers{nullptr, &*defaults}, ignored, r);
      // Every key [defaults] may hold is declared by now.
      defaults->finish();
    }
  }

  const toml::node* ports = root.get("port");
  if (!ports) {
    r.error(table.source(), "no [[port]]: a rack has at least one DeviceNet port");
    return config;
  }
  const toml::array* list = ports->as_array();
  if (list && list->empty()) {
    r.error(ports->source(), "port is empty: a rack has at least one DeviceNet port");
    return config;
  }
  if (!list || !list->is_array_of_tables()) {
    r.error(ports->source(), fmt::format("port must be an array of tables: write [[port]], not {}",
                                         ports->is_table() ? "[port]" : type_name(ports->type())));
    return config;
  }
  std::map<std::string, std::uint32_t> names;
  std::map<std::string, std::string> interfaces;
  for (const toml::node& element : *list) {
    const toml::table& pt = *element.as_table();
    PortConfig port = read_port(pt, config, defaults ? &*defaults : nullptr, ctx, r);
    if (!port.name.empty()) {
      const toml::node* name_node = pt.get("name");
      auto [it, added] = names.try_emplace(port.name, line_of(name_node->source()));
      if (!added) {
        r.error(name_node->source(),
                fmt::format("port name \"{}\" is already used by the port at line {}", port.name,
                            it->second));
      }
    }
    if (!port.interface.empty() && port.interface != kSimulatedInterface) {
      auto [it, added] = interfaces.try_emplace(port.interface, port.name);
      if (!added) {
        r.error(pt.get("interface")->source(),
                fmt::format("interface \"{}\" is already used by port \"{}\"", port.interface,
                            it->second));
      }
    }
    config.ports.push_back(std::move(port));
  }
  return config;
}

}  // namespace

ConfigError::ConfigError(std::vector<std::string> problems)
    : std::runtime_error(toml_config::join_lines(problems)), problems_(std::move(problems)) {}

std::string_view to_string(NoCommanderPolicy policy) noexcept {
  switch (policy) {
    case NoCommanderPolicy::kIdle:
      return "idle";
    case NoCommanderPolicy::kHoldLastOutputs:
      return "hold";
  }
  return "?";
}

DaemonConfig parse_config(std::string_view text, std::string_view source_name,
                          const std::filesystem::path& base_dir) {
  Problems r{std::string(source_name)};
  const auto root = toml_config::parse(text, r);
  if (!root) throw ConfigError(r.errors());
  ReadContext ctx{base_dir, {}};
  DaemonConfig config = read_rack(*root, source_name, ctx, r);
  if (r.has_errors()) throw ConfigError(r.errors());
  config.warnings = r.warnings();
  return config;
}

DaemonConfig load_config_file(const std::filesystem::path& path) {
  auto file = toml_config::read_file(path, "a configuration file");
  if (!file.text) throw ConfigError({std::move(file.error)});
  DaemonConfig config =
      parse_config(*file.text, path.string(), std::filesystem::absolute(path).parent_path());
  // [security]'s relative paths are the configuration file's neighbours.
  if (config.security) {
    config.security->resolve_relative_to(std::filesystem::absolute(path).parent_path());
  }
  return config;
}

DaemonConfig embedded_default_config() {
  return parse_config(embedded_default_config_text(), "embedded default");
}

rack::PumpConfig NodeSettings::cdn127_pump() {
  rack::PumpConfig p;
  p.io = cdn127::preset(cdn127::ConfigurationPreset::kCdn127);
  return p;
}

rack::DeviceConfig NodeSettings::device() const {
  rack::DeviceConfig d;
  d.node = pump.node;
  d.no_commander = pump.no_commander;
  d.resume = pump.resume;
  d.command_refresh = pump.command_refresh;
  d.eds = eds;
  d.eds_path = eds_path;
  d.eds_digest = eds_digest;
  d.settings = eds_node;
  return d;
}

rack::PortNodes to_port_nodes(const PortConfig& port) {
  rack::PortNodes out(std::vector<rack::PumpConfig>{}, std::vector<rack::DeviceConfig>{});
  for (const auto& n : port.nodes) {
    if (n.is_eds()) {
      out.of<rack::DeviceConfig>().push_back(n.device());
    } else {
      out.of<rack::PumpConfig>().push_back(n.pump);
    }
  }
  return out;
}

std::vector<rack::PumpConfig> to_pump_configs(const PortConfig& port) {
  return to_port_nodes(port).of<rack::PumpConfig>();
}

devicenet::ScannerConfig to_scanner_config(const PortConfig& port, std::string_view host_id) {
  devicenet::ScannerConfig c = port.master;
  c.serial_number = port.master_serial_number.value_or(derived_master_serial(host_id, port.name));
  return c;
}

}  // namespace dnbridge::daemon
