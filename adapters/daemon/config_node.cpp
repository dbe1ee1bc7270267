// The keys a node and [defaults] share: the profile, the node's timings
// (poll period, packet rates, response timeouts), publishing, no_commander,
// command_refresh_ms and resume; each a node's own, else [defaults]', else
// the built-in value. A profile's own keys: config_node_cdn127.cpp,
// config_node_eds.cpp.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "adapters/daemon/config_internal.hpp"

namespace dnbridge::daemon::config_detail {

using toml_config::read_bool;
using toml_config::read_number;
using toml_config::read_string;

namespace {

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

// The poll timings: poll_period_ms, expected_packet_rate_ms,
// explicit_packet_rate_ms, immediate_poll, immediate_poll_min_gap_ms and
// publish_max_period_ms; the expected packet rate, the gap and the publish
// period are checked against the poll period.
void read_poll_timing(const Layers& layers, NodeSettings& s, Problems& r) {
  const Found poll = layers.find("poll_period_ms");
  const Found epr = layers.find("expected_packet_rate_ms");
  bool poll_ok = true, epr_ok = true;
  if (poll.value) {
    auto v = read_key_ms(*poll.value, KeyPlace::kNode, "poll_period_ms", r);
    poll_ok = v.has_value();
    if (v) s.pump.node.poll_period = *v;
  }
  if (epr.value) {
    auto v = read_key_ms(*epr.value, KeyPlace::kNode, "expected_packet_rate_ms", r);
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
    if (auto v = read_key_ms(*f.value, KeyPlace::kNode, "explicit_packet_rate_ms", r)) {
      s.pump.node.explicit_packet_rate = *v;
    }
  }
  if (Found f = layers.find("immediate_poll"); f.value) {
    if (auto v = read_bool(*f.value, "immediate_poll", r))
      s.pump.node.immediate_poll_on_change = *v;
  }
  if (const Found gap = layers.find("immediate_poll_min_gap_ms"); gap.value) {
    if (auto v = read_key_ms(*gap.value, KeyPlace::kNode, "immediate_poll_min_gap_ms", r)) {
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
    if (auto v = read_key_ms(*f.value, KeyPlace::kNode, "publish_max_period_ms", r)) {
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
}

}  // namespace

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
  // (read_eds_node), [defaults] may hold them for the CDN127s whatever
  // profile it gives the others.
  const bool cdn127 = s.profile == kProfileCdn127 || !layers.per_node();
  if (Found f = layers.find("io"); f.value && cdn127) {
    if (auto v = read_io(*f.value, r)) s.pump.io = *v;
  }
  if (Found f = layers.find("identity"); f.value && cdn127) {
    if (auto v = read_identity(*f.value, r)) s.pump.identity = *v;
  }

  read_poll_timing(layers, s, r);
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
    if (auto v = read_key_ms(*f.value, KeyPlace::kNode, "explicit_response_timeout_ms", r)) {
      s.pump.node.explicit_response_timeout = *v;
    }
  }
  if (Found f = layers.find("poll_response_timeout_ms"); f.value) {
    if (auto v = read_key_ms(*f.value, KeyPlace::kNode, "poll_response_timeout_ms", r)) {
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

std::optional<bool> read_safe_state_source(const toml::node& n, Problems& r) {
  auto v = read_string(n, "safe_state", r);
  if (!v) return std::nullopt;
  if (*v == "configured") return false;
  if (*v == "device") return true;
  r.error(n.source(),
          fmt::format("safe_state = \"{}\" is not a choice: use \"configured\" (the default: the "
                      "fault and idle actions this file gives are downloaded) or \"device\" "
                      "(the device's own, fixed by its maker)",
                      *v));
  return std::nullopt;
}

void refuse_other_profiles_keys(TableReader& node, std::uint8_t profile, Problems& r) {
  for (std::string_view key : keys_of_other_profiles(profile)) {
    if (const toml::node* n = node.get(key)) r.error(n->source(), other_profile_key(profile, key));
  }
}

}  // namespace dnbridge::daemon::config_detail
