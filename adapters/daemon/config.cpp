// The configuration's top level (rack, domain, log_level, [explicit_policy],
// [metrics], [security], [defaults], the list of [[port]]) and the public
// functions of config.hpp. A port's keys: config_port.cpp; a node's:
// config_node*.cpp.
#include "adapters/daemon/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "adapters/daemon/config_internal.hpp"
#include "adapters/daemon/host_identity.hpp"
#include "adapters/security/toml_settings.hpp"
#include "adapters/toml_config/reader.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::daemon {

namespace cdn127 = profiles::cdn127;

namespace config_detail {
namespace {

using toml_config::read_bool;
using toml_config::read_int_as;
using toml_config::read_name;
using toml_config::read_string;
using toml_config::type_name;

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
  table.allow_only(key_names(KeyPlace::kExplicitPolicy));
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
  table.allow_only(key_names(KeyPlace::kMetrics));
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

DaemonConfig read_rack(const toml::table& table, std::string_view source, ReadContext& ctx,
                       Problems& r) {
  TableReader root(table, "the top level", r);
  root.allow_only(key_names(KeyPlace::kTop),
                  [](std::string_view key) { return misplaced_key(KeyPlace::kTop, false, key); });
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
    const KeyRange b = bounds_of(KeyPlace::kTop, "domain");
    const std::string note = fmt::format("a DDS domain ID is {}..{}", b.min, b.max);
    if (auto v = read_int_as<std::uint32_t>(*n, "domain", {b.min, b.max, {}, note}, r)) {
      config.domain_id = *v;
    }
  }
  if (const toml::node* n = root.get("master_mac")) {
    if (auto v = read_mac(*n, "master_mac", r)) config.master_mac = *v;
  }
  if (const toml::node* n = root.get("max_commander_lease_ms")) {
    if (auto v = read_key_ms(*n, KeyPlace::kTop, "max_commander_lease_ms", r)) {
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
    config.security = security::read_table(*n, r, key_names(KeyPlace::kSecurity));
  }

  if (const toml::node* n = root.get("metrics")) {
    config.metrics_listen = read_metrics(*n, r);
  }

  std::optional<TableReader> defaults;
  if (const toml::node* n = root.get("defaults")) {
    if (const toml::table* t = toml_config::as_table(*n, "defaults", "[defaults]", r)) {
      defaults.emplace(*t, "[defaults]", r);
      defaults->allow_only(defaults_key_names(), [](std::string_view key) {
        return misplaced_key(KeyPlace::kNode, true, key);
      });
      // Read once on their own, so that their problems are reported even
      // when no node inherits them.
      NodeSettings ignored;
      read_node_settings(Layers{nullptr, &*defaults}, ignored, r);
      NodeSettings ignored_eds;
      ignored_eds.profile = kProfileEds;
      read_eds_node(Layers{nullptr, &*defaults}, ctx, ignored_eds, r);
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
}  // namespace config_detail

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
  toml_config::Problems r{std::string(source_name)};
  const auto root = toml_config::parse(text, r);
  if (!root) throw ConfigError(r.errors());
  config_detail::ReadContext ctx{base_dir, {}};
  DaemonConfig config = config_detail::read_rack(*root, source_name, ctx, r);
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
