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
    // The same key read again (a [defaults]' eds, for each node that
    // inherits it) has its problems listed already.
    if (!e.file && line_of(key.source()) != e.first_line) {
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
  const profiles::eds::Parsed parsed = profiles::eds::parse(*text.text);
  for (const auto& problem : parsed.problems) {
    const std::string line = fmt::format("eds: {}", profiles::eds::format_problem(path, problem));
    if (problem.severity == profiles::eds::Problem::Severity::kError) {
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
    e.file = std::make_shared<const profiles::eds::EdsFile>(*parsed.file);
    e.digest = digest_of(*text.text);
  }
  return e;
}

// connection = "poll" | "bit-strobe" | "change-of-state" | "cyclic".
std::optional<profiles::eds::ConnectionKind> read_connection(const toml::node& n, Problems& r) {
  auto v = read_string(n, "connection", r);
  if (!v) return std::nullopt;
  static constexpr std::pair<std::string_view, profiles::eds::ConnectionKind> kKinds[] = {
      {"poll", profiles::eds::ConnectionKind::kPoll},
      {"bit-strobe", profiles::eds::ConnectionKind::kStrobe},
      {"change-of-state", profiles::eds::ConnectionKind::kChangeOfState},
      {"cyclic", profiles::eds::ConnectionKind::kCyclic}};
  for (const auto& [name, kind] : kKinds) {
    if (*v == name) return kind;
  }
  r.error(n.source(), fmt::format("connection = \"{}\" is not a connection: use \"poll\", "
                                  "\"bit-strobe\", \"change-of-state\" or \"cyclic\"",
                                  *v));
  return std::nullopt;
}

// KEY = [{ name = "...", value = N }, ...]: EDS parameters by name, in order.
std::optional<std::vector<profiles::eds::ParameterValue>> read_parameter_values(
    const toml::node& n, std::string_view key, Problems& r) {
  const toml::array* list = n.as_array();
  if (!list || (!list->empty() && !list->is_array_of_tables())) {
    r.error(n.source(), fmt::format("{} must be an array of {{ name = \"...\", value = ... }}, "
                                    "not {}",
                                    key, type_name(n.type())));
    return std::nullopt;
  }
  std::vector<profiles::eds::ParameterValue> out;
  bool ok = true;
  for (const toml::node& element : *list) {
    TableReader t(*element.as_table(), std::string(key), r);
    t.allow_only(key_names(KeyPlace::kParameter));
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
// change-of-state or cyclic connection; [defaults] read alone takes each
// as it stands, the node it is for not known. Gives the `connection` key,
// if any.
const toml::node* read_eds_connection(const Layers& layers, NodeSettings& s, Problems& r) {
  const toml::node* connection = layers.find("connection").value;
  bool connection_known = true;
  if (connection) {
    auto v = read_connection(*connection, r);
    if (v) s.eds_node.connection = *v;
    connection_known = v.has_value();
  }
  // The change-of-state or cyclic connection's own settings. A node's own
  // value that its connection does not take is an error; one it inherits
  // from [defaults] is for the nodes it fits, and left by the others.
  const bool cos = s.eds_node.connection == profiles::eds::ConnectionKind::kChangeOfState ||
                   s.eds_node.connection == profiles::eds::ConnectionKind::kCyclic;
  const bool cyclic = s.eds_node.connection == profiles::eds::ConnectionKind::kCyclic;
  const Found heartbeat = layers.find("heartbeat_ms");
  const Found inhibit = layers.find("inhibit_ms");
  const Found acknowledged = layers.find("acknowledged");
  if (!connection_known) return connection;
  const auto own = [](const Found& f) { return f.level == Level::kNode; };
  const auto takes = [&](const Found& f, std::string_view key) {
    if (!layers.per_node()) return true;  // [defaults] alone: each as it stands
    if (cos) return true;
    if (own(f)) {
      r.error(f.value->source(),
              fmt::format("{} is for connection = \"change-of-state\" or \"cyclic\" (this "
                          "node's is \"{}\")",
                          key, to_string(s.eds_node.connection)));
    }
    return false;
  };
  if (heartbeat.value && takes(heartbeat, "heartbeat_ms")) {
    if (auto v = read_key_ms(*heartbeat.value, KeyPlace::kNode, "heartbeat_ms", r)) {
      s.eds_node.heartbeat = *v;
    }
  }
  if (acknowledged.value && takes(acknowledged, "acknowledged")) {
    if (auto v = read_bool(*acknowledged.value, "acknowledged", r)) s.eds_node.acknowledged = *v;
  }
  if (inhibit.value && takes(inhibit, "inhibit_ms")) {
    if (layers.per_node() && cyclic) {
      if (own(inhibit)) {
        r.error(inhibit.value->source(),
                "inhibit_ms is for connection = \"change-of-state\": a cyclic "
                "connection produces every heartbeat_ms, changes or not");
      }
    } else if (auto v = read_key_ms(*inhibit.value, KeyPlace::kNode, "inhibit_ms", r)) {
      s.eds_node.inhibit = *v;
      // Compared per node, where one of the two is the node's own; reported
      // where the more specific of the two is written.
      if (layers.per_node() && *v >= s.eds_node.heartbeat && (own(inhibit) || own(heartbeat))) {
        const bool at_inhibit = inhibit.level >= heartbeat.level;
        const Found& here = at_inhibit ? inhibit : heartbeat;
        r.error(here.value->source(),
                fmt::format("inhibit_ms = {}{} is not shorter than heartbeat_ms = {}{}: "
                            "changes could never be sent sooner than heartbeats",
                            std::chrono::duration_cast<milliseconds>(*v).count(),
                            at_inhibit ? std::string() : origin(inhibit),
                            std::chrono::duration_cast<milliseconds>(s.eds_node.heartbeat).count(),
                            at_inhibit ? origin(heartbeat) : std::string()));
      }
    }
  }
  return connection;
}

// safe_state ("configured" or "device", as for every profile) and
// safe_state_parameters, the parameters that set the outputs' fault and
// idle actions. A node's safe_state = [ ... ] is the same as
// safe_state_parameters = [ ... ], said in a warning. Gives the key the
// safe state's problems are reported at, if any.
const toml::node* read_eds_safe_state(const Layers& layers, NodeSettings& s, Problems& r) {
  const Found source = layers.find("safe_state");
  const Found params = layers.find("safe_state_parameters");
  const toml::node* values = params.value;
  Level values_level = params.level;
  if (source.value && source.value->is_array() && source.level == Level::kNode) {
    r.warning(source.value->source(),
              "safe_state = [ ... ] is read as safe_state = \"configured\" with "
              "safe_state_parameters = [ ... ]: write it so (safe_state says \"configured\" or "
              "\"device\" for every profile)");
    if (params.value && params.level == Level::kNode) {
      r.error(params.value->source(),
              "safe_state_parameters and safe_state = [ ... ] both give the parameters: keep "
              "safe_state_parameters");
      return params.value;
    }
    values = source.value;
    values_level = Level::kNode;
  } else if (source.value) {
    if (auto device = read_safe_state_source(*source.value, r)) {
      s.eds_node.safe_state_of_device = *device;
    }
  }
  if (values == nullptr) return source.value;
  // A node that keeps the device's values and gives values of its own says
  // two things; [defaults] may give values other nodes use (read alone, it
  // has them checked).
  if (s.eds_node.safe_state_of_device && layers.per_node()) {
    if (values_level == Level::kNode) {
      r.error(values->source(),
              fmt::format("safe_state_parameters has no effect with safe_state = \"device\"{}: "
                          "the device's own fault and idle actions are kept",
                          origin(source)));
    }
    return source.value;
  }
  if (auto v = read_parameter_values(
          *values, values == source.value ? "safe_state" : "safe_state_parameters", r)) {
    s.eds_node.safe_state = *v;
  }
  return values;
}

// The outputs' safe state as the node's EDS and settings leave it, in
// warnings: the device's own, or the parameters nobody set.
void warn_of_safe_state(const EdsRead& e, const toml::node& eds_key, const toml::node* safe,
                        NodeSettings& s, Problems& r) {
  const auto& io = profiles::eds::node_io(*e.file, s.eds_node.connection);
  if (!io || io->consumed.size == 0) return;
  if (s.eds_node.safe_state_of_device) {
    const auto names = [](const std::vector<const profiles::eds::Param*>& params) {
      std::string text;
      for (const profiles::eds::Param* p : params) {
        text += fmt::format("{}Param{} \"{}\"", text.empty() ? "" : ", ", p->number, p->name);
      }
      return text;
    };
    const profiles::eds::DeviceSafeState d = profiles::eds::device_safe_state(*e.file, s.eds_node);
    const toml::source_region& at = safe ? safe->source() : eds_key.source();
    r.warning(at, fmt::format("node {}: its outputs' fault and idle behaviour is the device's own "
                              "(safe_state = \"device\"): {}, never written",
                              s.pump.node.mac.value(),
                              d.read.empty() ? std::string("its EDS names no parameter to read")
                                             : "read at start-up: " + names(d.read)));
    if (!d.unread.empty()) {
      r.warning(at, fmt::format("node {}: {} not read (no link path to an attribute, or not of 1, "
                                "2 or 4 bytes): not shown",
                                s.pump.node.mac.value(), names(d.unread)));
    }
    if (!d.written.empty()) {
      r.warning(at, fmt::format("node {}: {} set in parameters although safe_state = \"device\": "
                                "written all the same",
                                s.pump.node.mac.value(), names(d.written)));
    }
    return;
  }
  for (const profiles::eds::Param* p :
       profiles::eds::safe_state_left_to_device(*e.file, s.eds_node)) {
    r.warning(eds_key.source(),
              fmt::format("node {}: Param{} \"{}\" is set neither in safe_state_parameters nor "
                          "in parameters: the device keeps its own value",
                          s.pump.node.mac.value(), p->number, p->name));
  }
}

}  // namespace

// A profile = "eds" node's own keys: eds (the file, relative to the
// configuration's directory), connection, parameters, safe_state and
// safe_state_parameters, each the node's own, else [defaults]'; checked
// against the EDS as the master will take them. [defaults] read alone
// (layers.node null) has its values and its EDS file checked as they stand.
void read_eds_node(const Layers& layers, ReadContext& ctx, NodeSettings& s, Problems& r) {
  const toml::node* connection = read_eds_connection(layers, s, r);
  const toml::node* parameters = layers.find("parameters").value;
  if (parameters) {
    if (auto v = read_parameter_values(*parameters, "parameters", r)) s.eds_node.parameters = *v;
  }
  const toml::node* safe = read_eds_safe_state(layers, s, r);
  const toml::node* key = layers.find("eds").value;
  if (!key) {
    if (layers.per_node()) {
      r.error(layers.node->table().source(),
              "missing required key 'eds' in [[port.node]] (a profile = \"eds\" node's EDS "
              "file, its own or [defaults]')");
    }
    return;
  }
  auto given = read_string(*key, "eds", r);
  if (!given) return;
  std::filesystem::path path(*given);
  if (path.is_relative() && !ctx.base_dir.empty()) path = ctx.base_dir / path;
  s.eds_path = path.lexically_normal().string();
  const EdsRead& e = read_eds_file(s.eds_path, *key, ctx, r);
  if (!e.file || !layers.per_node()) return;
  s.eds = e.file;
  s.eds_digest = e.digest;
  warn_of_safe_state(e, *key, safe, s, r);
  std::string why;
  if (!profiles::eds::make_node_profile(e.file, s.eds_node, &why)) {
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
