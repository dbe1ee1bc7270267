#include "adapters/sim/host/device_config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <span>
#include <tuple>
#include <utility>

#include "adapters/sim/world/sim_rack.hpp"
#include "adapters/toml_config/reader.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::sim::host {
namespace {

using devicenet::MacId;
using toml_config::type_name;

using toml_config::Problems;
using toml_config::TableReader;

// A delay longer than any master's timeout is still a reading worth trying;
// a minute bounds typing mistakes.
constexpr std::int64_t kMaxDelayMs = 60000;
// The expected packet rate is a UINT of milliseconds.
constexpr std::int64_t kMaxResolutionMs = 0xFFFF;

constexpr sim::ClassAttribute kIdentityState{profiles::cdn127::class_id::kIdentity, 8};

// The keys of a CDN127's readings (read_settings), refused by name on a
// device that runs its EDS file.
constexpr std::array<std::string_view, 11> kReadingKeys{"configuration_locked_while_poll_allocated",
                                                        "poll_paths_fixed",
                                                        "idle_poll_answered_empty",
                                                        "no_ack_of_last_request_fragment",
                                                        "release_keeps_outputs",
                                                        "identity_state_supported",
                                                        "unsafe_factory_output_actions",
                                                        "explicit_response_delay_ms",
                                                        "poll_response_delay_ms",
                                                        "epr_resolution_ms",
                                                        "serial_number_bytes"};

// The settings a [[device]] and [defaults] both hold.
DeviceSettings read_settings(TableReader& t) {
  Problems& p = t.problems();
  DeviceSettings s;
  auto flag = [&](std::string_view key, std::optional<bool>& out) {
    if (const toml::node* n = t.get(key)) out = toml_config::read_bool(*n, key, p);
  };
  auto ms = [&](std::string_view key, std::int64_t min, std::int64_t max,
                std::optional<Duration>& out) {
    if (const toml::node* n = t.get(key)) out = toml_config::read_ms(*n, key, min, max, p);
  };
  flag("configuration_locked_while_poll_allocated", s.configuration_locked_while_poll_allocated);
  flag("poll_paths_fixed", s.poll_paths_fixed);
  flag("idle_poll_answered_empty", s.idle_poll_answered_empty);
  flag("no_ack_of_last_request_fragment", s.no_ack_of_last_request_fragment);
  flag("release_keeps_outputs", s.release_keeps_outputs);
  flag("identity_state_supported", s.identity_state_supported);
  flag("unsafe_factory_output_actions", s.unsafe_factory_output_actions);
  ms("explicit_response_delay_ms", 0, kMaxDelayMs, s.explicit_response_delay);
  ms("poll_response_delay_ms", 0, kMaxDelayMs, s.poll_response_delay);
  ms("epr_resolution_ms", 1, kMaxResolutionMs, s.epr_resolution);
  if (const toml::node* n = t.get("serial_number_bytes")) {
    constexpr auto kAny = std::numeric_limits<std::int64_t>::max();
    if (auto v = toml_config::read_integer(*n, "serial_number_bytes", {-kAny, kAny}, p)) {
      if (*v == 2 || *v == 4) {
        s.serial_number_udint = *v == 4;
      } else {
        p.error(n->source(), fmt::format("serial_number_bytes = {}: 2 (UINT, as the manual's "
                                         "table types it) or 4 (UDINT, as ODVA's Identity)",
                                         *v));
      }
    }
  }
  return s;
}

// eds = "FILE": read and parsed; its problems at the key, with the EDS's
// own FILE:LINE.
std::optional<EdsDevice> read_eds(const toml::node& key, const std::filesystem::path& base_dir,
                                  Problems& p) {
  const toml::value<std::string>* given = key.as_string();
  if (given == nullptr) {
    p.error(key.source(),
            fmt::format("eds must be a string (a file), not {}", type_name(key.type())));
    return std::nullopt;
  }
  std::filesystem::path path(given->get());
  if (path.is_relative() && !base_dir.empty()) path = base_dir / path;
  EdsDevice d;
  d.path = path.lexically_normal().string();
  auto text = toml_config::read_file(d.path, "an EDS file");
  if (!text.text) {
    p.error(key.source(), fmt::format("eds: {}", text.error));
    return std::nullopt;
  }
  const profiles::eds::Parsed parsed = profiles::eds::parse(*text.text);
  for (const auto& problem : parsed.problems) {
    if (problem.severity == profiles::eds::Problem::Severity::kError) {
      p.error(key.source(), fmt::format("eds: {}", profiles::eds::format_problem(d.path, problem)));
    }
  }
  if (!parsed.file || parsed.errors > 0) return std::nullopt;
  d.file = std::make_shared<const profiles::eds::EdsFile>(*parsed.file);
  return d;
}

DeviceConfig read(const toml::table& table, Problems& p, const std::filesystem::path& base_dir) {
  DeviceConfig config;
  TableReader root(table, "the device configuration", p);
  if (const toml::node* n = root.get("defaults")) {
    if (const toml::table* t = toml_config::as_table(*n, "defaults", "[defaults]", p)) {
      TableReader defaults(*t, "[defaults]", p);
      config.defaults = read_settings(defaults);
    }
  }
  const toml::node* devices = root.get("device");
  if (devices == nullptr) return config;
  const auto* list = devices->as_array();
  if (list == nullptr || !list->is_array_of_tables()) {
    p.error(devices->source(), fmt::format("device must be an array of tables ([[device]]), not {}",
                                           type_name(devices->type())));
    return config;
  }
  std::map<unsigned, std::uint32_t> first_line;  // MAC -> line of its [[device]]
  for (const toml::node& n : *list) {
    TableReader t(*n.as_table(), "[[device]]", p);
    DeviceEntry entry;
    const toml::node* eds_key = t.get("eds");
    if (eds_key != nullptr) {
      const toml::node* e = eds_key;
      // A device driven by its EDS: the CDN127's readings are not its own.
      entry.eds = read_eds(*e, base_dir, p);
      if (const toml::node* s = t.get("serial_number")) {
        if (auto v = toml_config::read_integer(*s, "serial_number", {0, 0xFFFFFFFF}, p)) {
          if (entry.eds) entry.eds->serial_number = static_cast<std::uint32_t>(*v);
        }
      }
      if (const toml::node* m = t.get("member_lists")) {
        if (auto v = toml_config::read_bool(*m, "member_lists", p); v && entry.eds) {
          entry.eds->member_lists = *v;
        }
      }
      for (const auto& [key, value] : *n.as_table()) {
        if (std::find(kReadingKeys.begin(), kReadingKeys.end(), key.str()) == kReadingKeys.end()) {
          continue;  // its own keys, or unknown (the table reader says so)
        }
        (void)t.get(key.str());  // refused here, not as unknown
        p.error(value.source(), fmt::format("{} is a CDN127 reading: this device runs its EDS "
                                            "file",
                                            key.str()));
      }
    } else {
      entry.settings = read_settings(t);
    }
    const toml::node* mac = t.require("mac");
    if (mac == nullptr) continue;
    auto v = toml_config::read_integer(*mac, "mac", {0, devicenet::MacId::kMax}, p);
    if (!v) continue;
    entry.mac = MacId::from_bits(static_cast<std::uint8_t>(*v));
    if (eds_key != nullptr && !entry.eds) continue;  // its problems are reported
    const auto [it, added] = first_line.try_emplace(entry.mac.value(), mac->source().begin.line);
    if (!added) {
      p.error(mac->source(),
              fmt::format("mac = {} is given twice (first on line {})", *v, it->second));
      continue;
    }
    config.devices.push_back(entry);
  }
  return config;
}

}  // namespace

void DeviceSettings::apply_to(sim::SlaveOptions& o) const {
  if (configuration_locked_while_poll_allocated) {
    o.configuration_locked_while_poll_allocated = *configuration_locked_while_poll_allocated;
  }
  if (poll_paths_fixed) o.poll_paths_fixed = *poll_paths_fixed;
  if (idle_poll_answered_empty) o.idle_poll_answered_empty = *idle_poll_answered_empty;
  if (no_ack_of_last_request_fragment) {
    o.no_ack_of_last_request_fragment = *no_ack_of_last_request_fragment;
  }
  if (release_keeps_outputs) o.release_keeps_outputs = *release_keeps_outputs;
  if (explicit_response_delay) o.explicit_response_delay = *explicit_response_delay;
  if (poll_response_delay) o.poll_response_delay = *poll_response_delay;
  if (serial_number_udint) o.serial_number_udint = *serial_number_udint;
  if (epr_resolution) o.timer_resolution = *epr_resolution;
  // false: the simulator's factory values, not whatever a layer below set.
  if (unsafe_factory_output_actions) {
    o.factory_output_actions =
        *unsafe_factory_output_actions ? sim::kUnsafeFactoryOutputActions : sim::OutputActions{};
  }
  if (identity_state_supported) {
    auto& missing = o.unsupported_attributes;
    missing.erase(std::remove(missing.begin(), missing.end(), kIdentityState), missing.end());
    if (!*identity_state_supported) missing.push_back(kIdentityState);
  }
}

DeviceConfigError::DeviceConfigError(std::vector<std::string> problems)
    : std::runtime_error(toml_config::join_lines(problems)), problems_(std::move(problems)) {}

DeviceConfig parse_device_config(std::string_view text, std::string_view source_name,
                                 const std::filesystem::path& base_dir) {
  Problems problems{std::string(source_name)};
  const auto root = toml_config::parse(text, problems);
  if (!root) throw DeviceConfigError(problems.errors());
  DeviceConfig config = read(*root, problems, base_dir);
  if (problems.has_errors()) throw DeviceConfigError(problems.errors());
  return config;
}

DeviceConfig load_device_config(const std::filesystem::path& path) {
  auto file = toml_config::read_file(path, "a device configuration");
  if (!file.text) throw DeviceConfigError({std::move(file.error)});
  return parse_device_config(*file.text, path.string(), path.parent_path());
}

std::vector<DeviceSpec> device_options(const std::vector<MacId>& macs, const DeviceConfig& config,
                                       Reading reading) {
  std::vector<MacId> all;
  auto add = [&all](MacId mac) {
    if (std::find(all.begin(), all.end(), mac) == all.end()) all.push_back(mac);
  };
  for (MacId m : macs) add(m);
  for (const auto& d : config.devices) add(d.mac);

  std::vector<DeviceSpec> out;
  for (MacId mac : all) {
    DeviceSpec spec;
    const auto entry = std::find_if(config.devices.begin(), config.devices.end(),
                                    [&](const DeviceEntry& d) { return d.mac == mac; });
    if (entry != config.devices.end() && entry->eds) {
      spec.eds = entry->eds;
      spec.eds_options = sim::default_eds_slave_options(mac);
      if (entry->eds->serial_number) spec.eds_options.serial_number = *entry->eds->serial_number;
      spec.eds_options.member_lists = entry->eds->member_lists;
      out.push_back(std::move(spec));
      continue;
    }
    sim::SlaveOptions& o = spec.cdn127;
    o = sim::default_slave_options(mac);
    if (reading == Reading::kField) sim::apply_field_reading(o);
    config.defaults.apply_to(o);
    if (entry != config.devices.end()) entry->settings.apply_to(o);
    out.push_back(std::move(spec));
  }
  return out;
}

std::string describe_readings(const sim::SlaveOptions& o) {
  const sim::SlaveOptions lenient;
  std::vector<std::string> parts;
  if (o.configuration_locked_while_poll_allocated) {
    parts.emplace_back("configuration locked while poll allocated");
  }
  if (o.poll_paths_fixed) parts.emplace_back("poll paths fixed");
  if (o.idle_poll_answered_empty) parts.emplace_back("idle poll answered empty");
  if (o.no_ack_of_last_request_fragment) parts.emplace_back("no ack of last request fragment");
  if (o.release_keeps_outputs) parts.emplace_back("outputs kept on release");
  auto ms_of = [](Duration d) { return std::chrono::duration_cast<milliseconds>(d).count(); };
  if (o.explicit_response_delay > Duration::zero()) {
    parts.push_back(fmt::format("explicit responses {} ms late", ms_of(o.explicit_response_delay)));
  }
  if (o.poll_response_delay > Duration::zero()) {
    parts.push_back(fmt::format("poll responses {} ms late", ms_of(o.poll_response_delay)));
  }
  if (o.serial_number_udint) parts.emplace_back("4-byte serial number");
  if (std::find(o.unsupported_attributes.begin(), o.unsupported_attributes.end(), kIdentityState) !=
      o.unsupported_attributes.end()) {
    parts.emplace_back("no Identity State");
  }
  if (o.timer_resolution != lenient.timer_resolution) {
    parts.push_back(fmt::format("EPR in steps of {} ms", ms_of(o.timer_resolution)));
  }
  if (o.factory_output_actions == sim::kUnsafeFactoryOutputActions) {
    parts.emplace_back("unsafe factory output actions (every output holds on fault and idle)");
  } else if (o.factory_output_actions != lenient.factory_output_actions) {
    parts.emplace_back("own factory output actions");
  }
  if (parts.empty()) return "lenient";
  std::string out;
  for (const auto& p : parts) {
    if (!out.empty()) out += ", ";
    out += p;
  }
  return out;
}

}  // namespace dnbridge::sim::host
