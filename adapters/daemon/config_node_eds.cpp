// A profile = "eds" node's own keys: eds (its EDS file, read once per
// configuration), connection and the change-of-state or cyclic connection's
// settings, parameters and safe_state; checked against the EDS.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <chrono>
#include <initializer_list>
#include <utility>
#include <vector>

#include "adapters/daemon/config_internal.hpp"

namespace dnbridge::daemon::config_detail {

using toml_config::read_bool;
using toml_config::read_ms;
using toml_config::read_number;
using toml_config::read_string;
using toml_config::type_name;

namespace {

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

// connection, and heartbeat_ms, inhibit_ms and acknowledged for a
// change-of-state or cyclic connection. Gives the `connection` key, if any.
const toml::node* read_eds_connection(TableReader& nt, NodeSettings& s, Problems& r) {
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
  return connection;
}

}  // namespace

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
  const toml::node* connection = read_eds_connection(nt, s, r);
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

}  // namespace dnbridge::daemon::config_detail
