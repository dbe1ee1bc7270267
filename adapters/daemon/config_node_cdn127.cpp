// A CDN127 node's own keys: io (a preset, or the Configuration object's
// values), identity, and the safe state of its outputs (safe_state,
// pump_on_fault ... analog_output_on_idle).
#include <fmt/format.h>
#include <toml++/toml.h>

#include <array>
#include <initializer_list>
#include <string>

#include "adapters/daemon/config_internal.hpp"
#include "bridge/profiles/cdn127/objects.hpp"

namespace dnbridge::daemon::config_detail {

using toml_config::read_int_as;
using toml_config::read_integer;
using toml_config::read_number;
using toml_config::read_string;
using toml_config::type_name;

namespace {

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

}  // namespace

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
  table.allow_only(key_names(KeyPlace::kIo));
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
    const KeyRange b = bounds_of(KeyPlace::kIo, "mode");
    if (auto v = read_int_as<std::uint8_t>(*m, "io.mode", {b.min, b.max}, r)) {
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
    const KeyRange b = bounds_of(KeyPlace::kIo, "no_nc_mask");
    if (auto v = read_int_as<std::uint8_t>(*m, "io.no_nc_mask", {b.min, b.max}, r)) {
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
  table.allow_only(key_names(KeyPlace::kIdentity));
  devicenet::ExpectedIdentity id;
  bool ok = true;
  auto field = [&](std::string_view key, std::uint16_t& out) {
    const toml::node* v = table.require(key);
    const KeyRange b = bounds_of(KeyPlace::kIdentity, key);
    auto value =
        v ? read_int_as<std::uint16_t>(*v, fmt::format("identity.{}", key), {b.min, b.max}, r)
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

namespace {

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

}  // namespace

void read_safe_state(const Layers& layers, NodeSettings& s, Problems& r) {
  if (Found f = layers.find("safe_state"); f.value) {
    if (auto device = read_safe_state_source(*f.value, r)) {
      s.pump.safe_state.source =
          *device ? cdn127::SafeStateSource::kDevice : cdn127::SafeStateSource::kConfiguration;
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
              fmt::format("{} has no effect with safe_state = \"device\"{}: the device's own "
                          "fault and idle actions are kept",
                          k.key, origin(layers.find("safe_state"))));
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
    // Found: only a safe_state key sets the device's source.
    // NOLINTNEXTLINE(clang-analyzer-core.CallAndMessage)
    r.warning(f.value->source(),
              fmt::format("node {} keeps the device's own fault and idle actions "
                          "(safe_state = \"device\"): read and shown, never written",
                          s.pump.node.mac.value()));
  }
}

}  // namespace dnbridge::daemon::config_detail
